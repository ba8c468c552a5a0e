#pragma once
// Number lists as the commands take them: "0.05,0.10", stretch ranges "first:last:step",
// positive integer lists, "NX,NY" tilings. Every error names the option it came from.
#include <string>
#include <utility>
#include <vector>

namespace yarnhom {

// Comma-separated finite numbers; std::invalid_argument naming `what` otherwise.
std::vector<double> parse_numbers(const std::string& text, const std::string& what);

// Stretch ratios from "first:last:step" (inclusive of last up to rounding), as `strip`, `sim
// stretch` and `accuracy` take them.
std::vector<double> parse_stretch_range(const std::string& text);

// Positive integers up to `max`.
std::vector<int> parse_ints(const std::string& text, const std::string& what, int max = 1000000);

// "NX,NY": how many times a pattern's tile repeats along x and y in a patch RVE (`rve --tile`,
// `produce --tile`).
std::pair<int, int> parse_tiles(const std::string& text, const std::string& what);

}  // namespace yarnhom
