// Writers of the experiment results: per-run CSV, summary CSV / Markdown (Table II) and a PNG plot of the
// errors over time (OpenCV drawing). ROS-free.
#pragma once

#include <string>
#include <vector>

#include "picker_localisation/eval/metrics.h"
#include "picker_localisation/topology/topological_map.h"

namespace picker_localisation {
namespace eval {

// Header of summary.csv (exactly this, one line).
extern const char* const kSummaryCsvHeader;

// Per-run time series: stamp,picker_id,estimated_node,true_node,true_x,true_y,euclidean,topological,
// lane_applicable,in_true_lane. Throws std::runtime_error when the file cannot be written.
void writeRunCsv(const std::string& path, const topology::TopologicalMap& map,
                 const std::vector<ErrorSample>& samples);

// summary.csv: one row per method; the numeric fields of an unavailable method are the word `unavailable`.
void writeSummaryCsv(const std::string& path, const std::vector<MethodSummary>& rows);
std::string summaryCsv(const std::vector<MethodSummary>& rows);

// summary.md: a Markdown table (mean (std over runs), pooled std, right-lane share) with a title line.
void writeSummaryMarkdown(const std::string& path, const std::string& title,
                          const std::vector<MethodSummary>& rows);
std::string summaryMarkdown(const std::string& title, const std::vector<MethodSummary>& rows);

// Plain-text table of the errors per picker plus an `all` row (pickers pooled): samples, Euclidean mean/std
// [m], topological mean/std [nodes], right-lane share. Printed by the evaluator node at shutdown.
std::string errorTable(const std::vector<std::pair<std::string, std::vector<ErrorSample>>>& per_picker);

// Mean error over time of one method (all runs and pickers, binned).
struct ErrorSeries {
  std::string method;
  std::vector<double> t;            // bin centres, s
  std::vector<double> euclidean;    // m
  std::vector<double> topological;  // hops
};

// Bins the samples of every run by stamp (bin width in s, measured from `t0`) and averages each bin.
ErrorSeries binErrors(const std::string& method, const std::vector<std::vector<ErrorSample>>& runs, double t0,
                      double bin_width);

// Two panels (Euclidean error [m] above, topological error [hops] below) with one coloured line per method
// and a legend. Throws std::runtime_error when the image cannot be written.
void plotErrors(const std::string& path, const std::vector<ErrorSeries>& series, int width = 1000,
                int height = 700);

}  // namespace eval
}  // namespace picker_localisation
