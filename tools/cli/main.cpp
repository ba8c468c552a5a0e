// yarnhom: yarn-level cloth to neural continuum material models. One subcommand per
// tools/cmd_*.cpp file; each registers itself here.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <string>

#include <cstdlib>
#include <unistd.h>

#include "core/cluster.hpp"
#include "numerics/blas_threads.hpp"
#include "tools/cli/commands.hpp"

int main(int argc, char** argv) {
  // OpenBLAS on a CPU it does not recognize runs its slowest kernels: start again asking for
  // the ones the CPU supports (numerics/blas_threads.hpp). Once: the variable is then set. Only
  // the commands that factorize with CHOLMOD (whose supernodes are BLAS calls) pay for the second
  // start (about 0.1 s); the others never call the BLAS, and the commands that run stages start
  // the stages as processes of their own, which decide for themselves.
  const std::string first = argc > 1 ? argv[1] : "";
  const bool factorizes = first == "produce" || first == "rve" || first == "strip" || first == "sim";
  if (const char* kernels = factorizes ? yarnhom::numerics::blas_kernels_to_request() : nullptr) {
    setenv("OPENBLAS_CORETYPE", kernels, 1);
    execv("/proc/self/exe", argv);  // returns only on failure: carry on with the kernels we have
  }
  // Under mpirun (docs/produce.md, "On a cluster"): produce, accuracy and the accuracy studies
  // run on several ranks; any other command would run once per rank and write the same files.
  yarnhom::cluster::init(&argc, &argv);
  if (yarnhom::cluster::size() > 1) {
    const std::string command = argc > 1 ? argv[1] : "", sub = argc > 2 ? argv[2] : "";
    const bool study = command == "study" && (sub == "table5" || sub == "rve-size" || sub == "bake-resolution" ||
                                              sub == "strip-width" || sub == "--help" || sub == "-h");
    if (command != "produce" && command != "accuracy" && !study) {
      if (yarnhom::cluster::rank() == 0)
        std::fprintf(stderr, "yarnhom: error: '%s%s%s' was started by mpirun on %d ranks; only produce, accuracy and study "
                     "table5 | rve-size | bake-resolution | strip-width run on several ranks (run the others without "
                     "mpirun)\n", command.c_str(), sub.empty() ? "" : " ", sub.c_str(), yarnhom::cluster::size());
      return 2;
    }
  }
  CLI::App app{
      "yarnhom: turns yarn-level cloth into fast, stable continuum material models with neural "
      "networks (Feng et al. 2024, 'Neural-Assisted Homogenization of Yarn-Level Cloth').\n"
      "Pipeline: produce (yarn RVE data) -> train-all (one MLP per energy term) -> bake "
      "(Hermite tables) -> eval."};
  app.require_subcommand(1);
  app.set_help_all_flag("--help-all", "Print the help of every subcommand");
  for (auto reg : yarnhom::tools::command_registry()) reg(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const yarnhom::tools::ExitCode& e) {
    return e.code;
  } catch (const std::exception& e) {
    // On several ranks the others would wait for this one forever: end them all.
    if (yarnhom::cluster::size() > 1) yarnhom::cluster::abort(e.what());
    std::fprintf(stderr, "yarnhom: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
