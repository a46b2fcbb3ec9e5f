// One `compare` run, everything it writes, in one call (the tool only binds options and prints): the comparison
// (temporal/compare/comparison.h) with its pictures made while the frames stream (temporal/pictures), then the
// CSV, the JSON, the charts (temporal/plot, on a virtual display when needed) and the HTML report page.
//
// Outputs that fail do not stop the others: each failure is kept in CompareRun::output_errors (the tool exits 4
// after writing what it could). Usage errors (a bad option, an output that would replace an input) stop the run
// before anything is written.
#pragma once

#include "temporal/core/error.h"
#include "temporal/compare/comparison.h"
#include "temporal/pictures/comparison_pictures.h"

#include <string>
#include <vector>

namespace temporal {

struct CompareOutputs {
  std::string csv;             // per-frame CSV; empty: none
  std::string json;            // JSON summary; empty: none
  std::string plot;            // charts F.png / F.svg / F.pdf (temporal/plot/plot.h); empty: none
  std::string title;           // charts', sheet's and page's title; empty: the metric's name only
  PictureOptions pictures;     // --png DIR, --report DIR and how pictures look
  // Instead of comparing frames: the per-frame CSVs of shards of one comparison (disjoint frame ranges), merged
  // exactly (merge_comparison_csvs). Pictures, the report and error maps need the frames and are refused with it.
  std::vector<std::string> merge;
};

struct CompareRun {
  ComparisonReport report;
  std::vector<ThresholdFailure> failures;
  std::string table;                  // summary_table(report), for stdout
  std::vector<Error> output_errors;   // outputs not written (the run went on)
  std::string report_page;            // DIR/index.html when it was written
};

// Runs the comparison and writes every output asked for. The JSON and the page name `setup.tool` and
// `setup.parameters`. Errors: those of compare_sequences, and Usage for bad outputs (an extension --plot cannot
// write, an output that is one of the inputs, --sheet-frame outside the frames, a display space the OCIO config
// lacks, pictures or a report with `merge`, no reference or test without `merge`).
Expected<CompareRun> run_compare(const ComparisonSetup& setup, const Thresholds& thresholds,
                                 const CompareOutputs& outputs, const ComparisonHooks& hooks = {});

}  // namespace temporal
