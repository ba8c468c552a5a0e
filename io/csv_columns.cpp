#include "io/csv_columns.hpp"

#include <algorithm>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "core/file_checks.hpp"

namespace yarnhom {

namespace {

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string c;
  while (std::getline(ss, c, ',')) {
    const size_t a = c.find_first_not_of(" \t\r"), b = c.find_last_not_of(" \t\r");
    out.push_back(a == std::string::npos ? "" : c.substr(a, b - a + 1));
  }
  return out;
}

}  // namespace

CsvColumns read_csv_columns(const std::string& path, const std::vector<std::string>& only) {
  check_input_file(path);  // a FIFO would block the reader
  std::ifstream in(path);
  if (!in) throw FileError(path, "", "cannot open");
  std::vector<std::string> header;
  auto wanted = [&](const std::string& h) { return only.empty() || std::find(only.begin(), only.end(), h) != only.end(); };
  CsvColumns t;
  std::string line;
  int lineno = 0;
  while (std::getline(in, line)) {
    ++lineno;
    if (line.empty() || line[0] == '#' || line.find_first_not_of(" \t\r") == std::string::npos) continue;
    auto cells = split(line);
    if (header.empty()) {
      header = cells;
      for (const auto& h : header)
        if (wanted(h)) t[h];
      continue;
    }
    if (cells.size() != header.size())
      throw FileError(path, "line " + std::to_string(lineno),
                      std::to_string(cells.size()) + " cells, the header has " + std::to_string(header.size()));
    for (size_t k = 0; k < cells.size(); ++k) {
      if (!wanted(header[k])) continue;
      size_t used = 0;
      double x = 0;
      try {
        x = std::stod(cells[k], &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != cells[k].size() || cells[k].empty())
        throw FileError(path, "line " + std::to_string(lineno), "'" + cells[k] + "' in column " + header[k] + " is not a number");
      t[header[k]].push_back(x);
    }
  }
  if (header.empty()) throw FileError(path, "", "no header line");
  return t;
}

const std::vector<double>& csv_column(const CsvColumns& t, const std::vector<std::string>& names, const std::string& path) {
  for (const auto& n : names) {
    auto it = t.find(n);
    if (it != t.end()) return it->second;
  }
  std::string list;
  for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
  throw FileError(path, "", "no column named " + list);
}

}  // namespace yarnhom
