#pragma once
// Small helpers shared by the subcommands: number lists, option validators, output checks,
// thread counts, time formatting.
#include <CLI/CLI.hpp>
#include <omp.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/atomic_file.hpp"
#include "core/file_checks.hpp"
#include "core/terms.hpp"
#include "train/backend.hpp"

namespace yarnhom::tools {

inline std::vector<double> parse_numbers(const std::string& text, const std::string& what) {
  std::vector<double> v;
  size_t start = 0;
  while (start <= text.size()) {
    size_t end = text.find(',', start);
    if (end == std::string::npos) end = text.size();
    std::string item = text.substr(start, end - start);
    size_t used = 0;
    double x;
    try {
      x = std::stod(item, &used);
    } catch (const std::exception&) {
      throw std::invalid_argument(what + ": '" + item + "' is not a number");
    }
    if (used != item.size()) throw std::invalid_argument(what + ": '" + item + "' is not a number");
    // NaN and infinity are never a meaningful strain, size or coordinate.
    if (!std::isfinite(x)) throw std::invalid_argument(what + ": '" + item + "' is not a finite number");
    v.push_back(x);
    start = end + 1;
  }
  return v;
}

// Stretch ratios from "first:last:step" (inclusive of last up to rounding), as `strip`, `sim
// stretch` and `accuracy` take them.
inline std::vector<double> parse_stretch_range(const std::string& text) {
  const size_t a = text.find(':'), b = text.find(':', a == std::string::npos ? a : a + 1);
  if (a == std::string::npos || b == std::string::npos)
    throw std::invalid_argument("--stretch " + text + ": expected first:last:step, e.g. 1.0:1.7:0.05");
  const auto v = parse_numbers(text.substr(0, a) + "," + text.substr(a + 1, b - a - 1) + "," + text.substr(b + 1), "--stretch");
  if (!(v[2] > 0) || !(v[1] >= v[0]) || !(v[0] > 0) || !std::isfinite(v[1]))
    throw std::invalid_argument("--stretch " + text + ": need 0 < first <= last and step > 0");
  std::vector<double> out;
  for (int k = 0;; ++k) {
    const double x = v[0] + k * v[2];
    if (x > v[1] + 1e-9 * v[2]) break;
    out.push_back(x);
    if (k > 100000) throw std::invalid_argument("--stretch " + text + ": too many steps");
  }
  return out;
}

inline std::vector<int> parse_ints(const std::string& text, const std::string& what, int max = 1000000) {
  std::vector<int> out;
  for (double x : parse_numbers(text, what)) {
    if (!(x >= 1 && x <= max) || x != std::floor(x))
      throw std::invalid_argument(what + ": expected positive integers up to " + std::to_string(max));
    out.push_back(int(x));
  }
  return out;
}

// "NX,NY": how many times a pattern's tile repeats along x and y in a patch RVE (`rve --tile`,
// `produce --tile`).
inline std::pair<int, int> parse_tiles(const std::string& text, const std::string& what) {
  std::vector<int> v;
  try {
    v = parse_ints(text, what, 64);
  } catch (const std::invalid_argument&) {
    v.clear();
  }
  if (v.size() != 2) throw std::invalid_argument(what + ": expected two integers NX,NY in [1, 64], got '" + text + "'");
  return {v[0], v[1]};
}

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

// Before any work: refuses an output that must not be written (core/file_checks.hpp: a folder,
// a device, a FIFO, an input of the command, an uncreatable path) and removes the temporaries
// that killed runs left beside it, saying so. Returns the file that will be written (the
// target of a symbolic link).
inline std::string prepare_output(const std::string& path, const std::vector<std::string>& inputs,
                                  const std::string& option = "-o") {
  const std::string target = check_output_file(path, inputs, option);
  for (const std::string& t : AtomicOutput::remove_stale_temporaries(path))
    std::fprintf(stderr, "yarnhom: removed %s, a temporary file left by an interrupted run\n", t.c_str());
  return target;
}

inline int default_threads() { return omp_get_num_procs(); }

inline std::string format_seconds(double s) {
  char buf[32];
  if (s < 60)
    std::snprintf(buf, sizeof buf, "%.1fs", s);
  else if (s < 3600)
    std::snprintf(buf, sizeof buf, "%dm%02ds", int(s) / 60, int(s) % 60);
  else
    std::snprintf(buf, sizeof buf, "%dh%02dm", int(s) / 3600, (int(s) % 3600) / 60);
  return buf;
}

inline bool stderr_is_tty() { return ::isatty(2); }

}  // namespace yarnhom::tools
