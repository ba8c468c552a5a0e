// yarnhom synth: a dataset in the spec's format from the analytic energy of docs/synthetic.md.
#include <cstdio>

#include "core/dataset.hpp"
#include "core/synthetic.hpp"
#include "tools/cli_util.hpp"
#include "tools/commands.hpp"

namespace yarnhom::tools {

void register_synth(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "synth",
      "Write a dataset for all 14 terms sampled from a smooth analytic energy density (written "
      "out in docs/synthetic.md). It stands in for the yarn producer in tests, benchmarks and "
      "the demo; the file says so in its 'source' and 'note' attributes.");
  struct Opts {
    std::string out, preset = "quick";
  };
  auto o = std::make_shared<Opts>();
  cmd->add_option("-o,--output", o->out, "Dataset file to write (HDF5); written atomically")->required();
  cmd->add_option("--preset", o->preset,
                  "Sampling density: 'quick' (21 points per 1D term, 9 x 9 grid per 2D term) or "
                  "'paper' (100 points, 31 x 31 grid)")
      ->check(CLI::IsMember({"quick", "paper"}))
      ->capture_default_str();
  cmd->callback([o] {
    prepare_output(o->out, {});
    Dataset ds = make_synthetic_dataset(o->preset);
    write_dataset(o->out, ds);
    size_t n = 0;
    for (auto& t : ds.terms) n += t.n;
    std::printf("wrote %s: synthetic dataset, preset %s, %zu terms, %zu samples, psi0 = %.6g J/m^2\n",
                o->out.c_str(), o->preset.c_str(), ds.terms.size(), n, ds.psi0);
  });
}

}  // namespace yarnhom::tools
