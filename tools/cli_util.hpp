#pragma once
// Small helpers shared by the subcommands: number lists, thread counts, time formatting.
#include <omp.h>
#include <unistd.h>

#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

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
    v.push_back(x);
    start = end + 1;
  }
  return v;
}

inline std::vector<int> parse_ints(const std::string& text, const std::string& what) {
  std::vector<int> out;
  for (double x : parse_numbers(text, what)) {
    if (x != int(x) || x < 1) throw std::invalid_argument(what + ": expected positive integers");
    out.push_back(int(x));
  }
  return out;
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
