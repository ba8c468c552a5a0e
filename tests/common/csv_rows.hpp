#pragma once
// A numeric CSV file as the CLI tests read it (steps.csv, stretch.csv): the header line, then
// one row of doubles per line.
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace yarnhom::test {

// CSV text (a command's output) in the same form.
inline std::vector<std::vector<double>> parse_csv_rows(const std::string& text, std::string* header = nullptr) {
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);
  if (header) *header = line;
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    std::vector<double> r;
    std::stringstream ls(line);
    std::string cell;
    while (std::getline(ls, cell, ',')) r.push_back(std::stod(cell));
    rows.push_back(r);
  }
  return rows;
}

inline std::vector<std::vector<double>> read_csv_rows(const std::string& path, std::string* header = nullptr) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return parse_csv_rows(text.str(), header);
}

}  // namespace yarnhom::test
