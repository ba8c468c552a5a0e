#pragma once
// What the accuracy studies (pipeline/study.hpp) share: names, number cells, the Fig. 5 picture,
// the test of one row.
#include <filesystem>
#include <string>

#include "pipeline/accuracy_run.hpp"

namespace yarnhom::pipeline {

// The paper's short name of a pattern file: basket, stockinette, honeycomb, cartridge.
std::string paper_name(const std::string& pattern);

// A table cell: "-" for NaN.
std::string fmt(double x, const char* f = "%.2f");

// A study's progress before its part k (0-based) of n, work_done and work_total in any unit
// (tests, or weights): "part k+1 of n", then from the second part on the elapsed time and the
// time left if the rest costs what the parts so far cost per unit of work.
std::string study_progress(int k, int n, double elapsed, double work_done, double work_total);

// scripts/plot/NAME (pipeline/python_env.hpp).
std::string plot_script(const std::string& name);

// The study's test options for one row: its pattern and direction, the materials' folder and
// the test's own.
AccuracyOptions row_test(const AccuracyOptions& acc, const std::string& pattern, const std::string& direction,
                         const std::string& materials_dir, const std::string& out);

// "dN | H | rel" cells of a summary for a Markdown table (N/m, cm, %), and their CSV twin
// "dN,H,rel" (%.6g).
std::string summary_md(const AccuracySummary& s, const char* sep = " | ");
std::string summary_csv(const AccuracySummary& s);

// Fig. 5: the yarn strip and the neural continuum strip at the step nearest 130 %, side by side.
// Pictures are a bonus: a missing python or a failed plot is reported, not fatal.
void fig5(const AccuracyResult& r, const AccuracyOptions& a, const std::string& title, const std::filesystem::path& png);

}  // namespace yarnhom::pipeline
