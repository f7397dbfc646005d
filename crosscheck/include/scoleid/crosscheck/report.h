#pragma once
// report.md and its plots, from the JSON each verb leaves in the output directory
// (modes.json, trajectories.json, identify.json, whichever exist), so a report can be rebuilt
// from the files alone.
//
// Plots (gnuplot, PNG; skipped with a note when gnuplot is not installed), each with the CSV
// behind it:
//   modes.png      |chain/FE − 1| of the first modes against n (log–log) with an n^−2 guide
//                  (modes_convergence.csv)
//   overlay.png    chain and FE responses per sensor at the finest n, residual on the right axis
//                  (overlay.csv)
//   identify.png   |relative error| of each parameter against n, the extrapolated and FE-on-FE
//                  errors as horizontal lines (identify_convergence.csv)
// The summary: how far the modes, the trajectories and the parameters agree, and whether the
// identifier's reported uncertainty covers the error it actually made.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace scoleid::crosscheck {

struct ReportInputs {
  nlohmann::json modes, trajectories, identify;   // null when absent
};

// Reads the verbs' JSON from `dir` (absent files stay null), each checked as check_report_inputs does.
ReportInputs read_report_inputs(const std::string& dir);
// Checks that every present input is shaped as its verb writes it (the fields summary_lines and
// make_report read, with their types and sizes): else io::InputError naming the file (as in `dir`)
// and the field.
void check_report_inputs(const ReportInputs& in, const std::string& dir);

// The one-screen summary lines.
std::vector<std::string> summary_lines(const ReportInputs& in);

struct ReportFiles {
  std::vector<std::pair<std::string, std::string>> files;   // name, content
  std::vector<std::string> scripts;                          // of those, gnuplot scripts to run
};
// Everything `report` writes: report.md, the convergence CSVs and the gnuplot scripts.
// `overlay_csv_present`: whether overlay.csv exists (the overlay plot needs it).
ReportFiles make_report(const ReportInputs& in, bool overlay_csv_present);

}  // namespace scoleid::crosscheck
