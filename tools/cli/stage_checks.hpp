#pragma once
// accuracy and the studies run strip and sim as stages, with options of their own and the
// user's --strip-args and --sim-args. Those command lines are parsed and checked here, before
// the first stage starts, by the stage commands' own declarations and checks (a bad --size,
// --stretch, pattern, '--strip-args --bogus' or '--sim-args "--dt -1"' used to surface only as
// "stage strip failed ... see logs/strip.log", after the materials were made).
#include <CLI/CLI.hpp>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

namespace yarnhom::tools {

// args: the command line a stage would run, its command name first. Throw std::invalid_argument
// with the command's own message when the command would refuse it before any work. The strip's
// returns its clamp band (m), which the accuracy test gives the continuum strip.
double check_strip_stage(const std::vector<std::string>& args);  // tools/cli/cmd_strip.cpp
void check_sim_stage(const std::vector<std::string>& args);    // tools/cli/cmd_sim.cpp

// Parses args with app (whose subcommand's callback makes the command's checks); CLI11's parse
// errors become std::invalid_argument.
inline void parse_stage(CLI::App& app, std::vector<std::string> args) {
  std::reverse(args.begin(), args.end());  // CLI11 takes a vector from its end
  try {
    app.parse(args);
  } catch (const CLI::ParseError& e) {
    throw std::invalid_argument(e.what());
  }
}

}  // namespace yarnhom::tools
