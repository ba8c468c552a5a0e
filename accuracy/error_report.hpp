#pragma once
// `yarnhom error`: the metrics of spec section 9 for a model or a baked file: the quadratic
// expansion error E_I (supplement Eq. 5) per term and E (Eq. 4), the fit against the data in
// physical units with its verdict, a baked file's deviation from its network, and with
// `compare` the bake-resolution table (supplement Table 4 analogue).
#include <string>

namespace yarnhom {

struct ErrorReportOptions {
  std::string file, data, model, terms = "all", csv;  // data, model: "" = the ones the file names, if found
  int samples = 1024;                                  // per neighbourhood of Eq. 5
  bool compare = false;
};

// Prints the report on stdout; with `csv` also writes the per-term rows there (atomically).
void run_error_report(const ErrorReportOptions& o);

}  // namespace yarnhom
