// Tracking metrics of Navigate-and-Seek Sec. VI: Euclidean error of the estimated node to the true pose,
// topological error (hops from the estimated node to the node nearest the truth) and the share of time the
// estimate lies in the picker's true lane. Aggregation over time, pickers and runs. ROS-free.
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <string>
#include <vector>

#include "picker_localisation/topology/topological_map.h"

namespace picker_localisation {
namespace eval {

// One comparison of an estimate with the truth at one instant.
struct ErrorSample {
  double stamp = 0.0;  // s
  std::string picker_id;
  topology::NodeIndex estimated_node = topology::kInvalidNode;
  topology::NodeIndex true_node = topology::kInvalidNode;  // node nearest the true position
  Eigen::Vector2d true_position{0.0, 0.0};                 // map frame, m
  double euclidean = 0.0;  // m: |position(estimated_node) - true_position| in the xy-plane
  int topological = 0;  // hops between estimated_node and true_node in the undirected graph; -1 unreachable
  // Lane rule. The truth's lane is the lane of the node nearest the true position. When that node is in no
  // lane (headland, dock, junction: the picker is between lanes), `lane_applicable` is false and the sample
  // does NOT count towards the right-lane share (neither right nor wrong); `in_true_lane` then reports
  // whether the estimate is also outside every lane, for display only.
  bool lane_applicable = false;
  bool in_true_lane = false;
};

// Compares the estimated node with the true position. Throws std::out_of_range for an invalid node index.
ErrorSample computeError(const topology::TopologicalMap& map, topology::NodeIndex estimated_node,
                         const Eigen::Vector2d& true_position, double stamp = 0.0,
                         const std::string& picker_id = "");

// Averages of one run (all pickers pooled, every sample weighted equally).
struct RunMetrics {
  std::size_t samples = 0;
  double euclidean_mean = 0.0;    // m
  double euclidean_std = 0.0;     // m, population std over the samples
  double topological_mean = 0.0;  // hops, over samples whose topological error is defined (>= 0)
  double topological_std = 0.0;
  std::size_t unreachable = 0;    // samples with topological == -1 (excluded from the hop statistics)
  std::size_t lane_samples = 0;   // samples with lane_applicable
  double right_lane_share = 0.0;  // in_true_lane among lane_applicable samples; NaN when there is none
};

RunMetrics summariseRun(const std::vector<ErrorSample>& samples);

// One row of Table II: per-run averages aggregated over the runs of a method.
// *_mean: mean over runs of the per-run means; *_std: sample standard deviation (n-1) of the per-run means
// over the runs (0 for a single run). *_pooled_std: standard deviation over every sample of every run, which
// is what the paper's parenthesised numbers most likely are (they often exceed the mean). right_lane_share:
// mean over the runs that have lane samples (NaN when none does), right_lane_share_std the sample std of the
// per-run shares over those runs.
struct MethodSummary {
  std::string method;
  std::size_t runs = 0;
  bool available = true;
  std::string unavailable_reason;
  double euclidean_mean = 0.0, euclidean_std = 0.0, euclidean_pooled_std = 0.0;
  double topological_mean = 0.0, topological_std = 0.0, topological_pooled_std = 0.0;
  double right_lane_share = 0.0, right_lane_share_std = 0.0;
};

MethodSummary summariseMethod(const std::string& method, const std::vector<std::vector<ErrorSample>>& runs);
MethodSummary unavailableMethod(const std::string& method, const std::string& reason);

// Mean and sample standard deviation (n-1; 0 for fewer than two values).
void meanAndStd(const std::vector<double>& values, double& mean, double& stddev);

}  // namespace eval
}  // namespace picker_localisation
