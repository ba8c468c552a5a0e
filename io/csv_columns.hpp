#pragma once
// A numeric CSV with a header line, read into named columns (the force curves of `strip` and
// `sim stretch`). Lines starting with '#' and blank lines are skipped.
#include <map>
#include <string>
#include <vector>

namespace yarnhom {

using CsvColumns = std::map<std::string, std::vector<double>>;

// Throws FileError naming the file and line for a missing header, a row of the wrong length or
// a cell that is not a number. With `only` given, just those columns (the ones present) are
// read and must be numeric; others may hold text (strip's force.csv has a status column).
CsvColumns read_csv_columns(const std::string& path, const std::vector<std::string>& only = {});

// The first of `names` present in the table; throws FileError listing them when none is.
const std::vector<double>& csv_column(const CsvColumns& t, const std::vector<std::string>& names, const std::string& path);

}  // namespace yarnhom
