#pragma once
// What the subcommands (tools/cli/cmd_*.cpp) share: the command and its options struct, the
// option groups several commands declare alike, and option validators. The number lists,
// output checks and time formatting the library functions use are core/number_list.hpp and
// core/console.hpp.
#include <CLI/CLI.hpp>

#include <cmath>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/console.hpp"
#include "core/file_checks.hpp"
#include "core/number_list.hpp"
#include "core/terms.hpp"
#include "tools/cli/command_help.hpp"
#include "tools/cli/commands.hpp"
#include "train/backend.hpp"
#include "yarn/rod/generate.hpp"

namespace yarnhom::tools {

// Option validators. CLI11's PositiveNumber and Range let NaN through (it compares false with
// everything) and accept infinity as a number; these refuse both.
inline CLI::Validator finite_range(double lo, double hi, const std::string& rule) {
  return CLI::Validator(
      [lo, hi, rule](std::string& in) -> std::string {
        double v;
        if (!CLI::detail::lexical_cast(in, v) || !std::isfinite(v)) return "'" + in + "' is not a finite number";
        if (v < lo || v > hi) return "'" + in + "' is out of range: " + rule;
        return "";
      },
      rule);
}
inline CLI::Validator finite_positive() {
  return CLI::Validator(
      [](std::string& in) -> std::string {
        double v;
        if (!CLI::detail::lexical_cast(in, v) || !std::isfinite(v)) return "'" + in + "' is not a finite number";
        if (!(v > 0)) return "'" + in + "' must be positive";
        return "";
      },
      "> 0");
}
inline CLI::Validator finite_non_negative() {
  return CLI::Validator(
      [](std::string& in) -> std::string {
        double v;
        if (!CLI::detail::lexical_cast(in, v) || !std::isfinite(v)) return "'" + in + "' is not a finite number";
        if (!(v >= 0)) return "'" + in + "' must not be negative";
        return "";
      },
      ">= 0");
}
// A list option that must name something: "--terms ''" used to mean "all terms".
inline CLI::Validator non_empty() {
  return CLI::Validator([](std::string& in) -> std::string { return in.empty() ? "must not be empty" : ""; }, "");
}
// An input file: must exist and be a regular file (a FIFO would block the reader).
inline CLI::Validator existing_regular_file() {
  return CLI::Validator(
      [](std::string& in) -> std::string {
        try {
          check_input_file(in);
        } catch (const std::exception& e) {
          return e.what();
        }
        return "";
      },
      "FILE");
}
// A term list ("0,02,15" or "all"; one term when single): refused at parse time when empty or
// naming an unknown term.
inline CLI::Validator term_list_validator(bool single = false) {
  return CLI::Validator(
      [single](std::string& in) -> std::string {
        if (in.empty()) return "empty term list (give terms such as 0,02 or 'all')";
        try {
          if (single) term_by_name(in);
          else parse_term_list(in);
        } catch (const std::exception& e) {
          return e.what();
        }
        return "";
      },
      single ? "TERM" : "TERMS");
}
// A training backend this build has.
inline CLI::Validator backend_validator() {
  return CLI::Validator(
      [](std::string& in) -> std::string {
        std::string list;
        for (const std::string& b : available_backends()) {
          if (b == in) return "";
          list += (list.empty() ? "" : ", ") + b;
        }
        return "unknown or unavailable backend '" + in + "' (this build has: " + list + ")";
      },
      "NAME");
}
// Threads: 0 means all cores; more than 1024 is a typo, not a machine.
inline constexpr int kMaxThreads = 1024;

// A subcommand of `parent`, described by its help text (tools/cli/command_help.hpp), and the
// options struct its callback reads (shared with the callback, which keeps it alive).
template <class Options>
std::pair<CLI::App*, std::shared_ptr<Options>> add_command(CLI::App& parent, const std::string& name) {
  auto options = std::make_shared<Options>();
  return {parent.add_subcommand(name, command_help(name)), options};
}

// The names of the subcommands `root` has (pipeline and accuracy refuse to run without theirs).
inline std::vector<std::string> command_names(CLI::App& root) {
  std::vector<std::string> names;
  for (CLI::App* sub : root.get_subcommands([](CLI::App*) { return true; })) names.push_back(sub->get_name());
  return names;
}

// The options given on the command line, by their long names ("--lr"): train's explicit values
// override its recipe's.
inline std::set<std::string> given_options(const CLI::App& cmd) {
  std::set<std::string> given;
  for (const CLI::Option* opt : cmd.get_options())
    if (opt->count() > 0)
      for (const std::string& n : opt->get_lnames()) given.insert("--" + n);
  return given;
}

// Option groups that several commands declare alike.
// PATTERN: a .pyp file or a built-in name; the help names exactly the built-in patterns
// (yarn::builtin_pattern_names), after the command's own words when it gives them.
inline CLI::Option* add_pattern_argument(CLI::App* cmd, std::string& pattern, const std::string& help = "") {
  const std::string names = yarn::builtin_pattern_list();
  return cmd
      ->add_option("PATTERN", pattern,
                   help.empty() ? "A .pyp file, or a built-in pattern: " + names : help + " (built-in: " + names + ")")
      ->required();
}
inline CLI::Option* add_output_option(CLI::App* cmd, std::string& out, const std::string& help,
                                      const std::string& flags = "-o,--output") {
  return cmd->add_option(flags, out, help)->required();
}
inline CLI::Option* add_threads_option(CLI::App* cmd, int& threads, const std::string& help, int least = 0) {
  return cmd->add_option("--threads", threads, help)->check(CLI::Range(least, kMaxThreads));
}
inline CLI::Option* add_preset_option(CLI::App* cmd, std::string& preset, const std::string& help, bool tiny = false) {
  const std::vector<std::string> presets = tiny ? std::vector<std::string>{"quick", "paper", "tiny"}
                                                : std::vector<std::string>{"quick", "paper"};
  return cmd->add_option("--preset", preset, help)->check(CLI::IsMember(presets))->capture_default_str();
}
inline CLI::Option* add_direction_option(CLI::App* cmd, std::string& direction, const std::string& help = "Stretch direction") {
  return cmd->add_option("--direction", direction, help)->check(CLI::IsMember({"course", "wale"}));
}
inline CLI::Option* add_epochs_option(CLI::App* cmd, int& epochs, const std::string& help) {
  return cmd->add_option("--epochs", epochs, help)->check(CLI::Range(0, 100000000))->capture_default_str();
}
inline CLI::Option* add_force_flag(CLI::App* cmd, bool& force) { return cmd->add_flag("--force", force, "Rerun every stage"); }
inline CLI::Option* add_quiet_flag(CLI::App* cmd, bool& quiet, const std::string& help) {
  return cmd->add_flag("-q,--quiet", quiet, help);
}
inline CLI::Option* add_yarn_material_option(CLI::App* cmd, std::string& material) {
  return cmd->add_option("--material", material,
                         "Yarn material: a file of 'key = value' lines, or a built-in name: hylc-calibrated (the "
                         "default), yarnhom-2025 (the constants before issue 10); docs/yarn_material.md");
}
inline CLI::Option* add_verbose_flag(CLI::App* cmd, bool& verbose) {
  return cmd->add_flag("--verbose", verbose, "One line per Newton iteration on stderr");
}

}  // namespace yarnhom::tools
