// Evaluation metrics against hand-computed values on the synthetic polytunnel (lane k at x = 1.5 k, lane
// nodes r<k>_<j> at y = 3 j, headland H<k> at y = -3, T<k> at y = 30), aggregation and the Table II writers.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "picker_localisation/eval/metrics.h"
#include "picker_localisation/eval/report.h"
#include "picker_localisation/topology/map_io.h"
#include "picker_localisation/topology/synthetic_map.h"

using namespace picker_localisation;
using namespace picker_localisation::eval;

namespace {
topology::TopologicalMap polytunnel() {
  return topology::makePolytunnelMap(topology::PolytunnelSpec{});
}
topology::NodeIndex idx(const topology::TopologicalMap& m, const std::string& n) {
  return *m.index(n);
}
}  // namespace

TEST(EvalMetrics, WrongLaneHandComputed) {
  const auto map = polytunnel();
  // Estimate r2_2 at (3, 6); truth at (4.4, 9.2): nearest node r3_3 at (4.5, 9).
  const ErrorSample s = computeError(map, idx(map, "r2_2"), Eigen::Vector2d(4.4, 9.2), 12.5, "p");
  EXPECT_EQ(s.true_node, idx(map, "r3_3"));
  EXPECT_NEAR(s.euclidean, std::hypot(1.4, 3.2), 1e-12);
  // r2_2 -> r2_1 -> r2_0 -> H2 -> H3 -> r3_0 -> r3_1 -> r3_2 -> r3_3: 8 hops.
  EXPECT_EQ(s.topological, 8);
  EXPECT_TRUE(s.lane_applicable);
  EXPECT_FALSE(s.in_true_lane);
  EXPECT_DOUBLE_EQ(s.stamp, 12.5);
  EXPECT_EQ(s.picker_id, "p");
}

TEST(EvalMetrics, SameLaneAndExactNode) {
  const auto map = polytunnel();
  const ErrorSample a = computeError(map, idx(map, "r5_4"), Eigen::Vector2d(7.5, 12.0));
  EXPECT_NEAR(a.euclidean, 0.0, 1e-12);
  EXPECT_EQ(a.topological, 0);
  EXPECT_TRUE(a.in_true_lane);
  const ErrorSample b = computeError(map, idx(map, "r5_1"), Eigen::Vector2d(7.6, 20.9));  // nearest r5_7
  EXPECT_EQ(b.topological, 6);
  EXPECT_NEAR(b.euclidean, std::hypot(0.1, 17.9), 1e-12);
  EXPECT_TRUE(b.in_true_lane);
}

TEST(EvalMetrics, TruthOutsideEveryLaneIsNotCounted) {
  const auto map = polytunnel();
  // Truth on the headland next to H4 (6, -3): lane rule not applicable.
  const ErrorSample in_lane_est = computeError(map, idx(map, "r4_0"), Eigen::Vector2d(6.0, -3.2));
  EXPECT_EQ(in_lane_est.true_node, idx(map, "H4"));
  EXPECT_FALSE(in_lane_est.lane_applicable);
  EXPECT_FALSE(in_lane_est.in_true_lane);
  EXPECT_EQ(in_lane_est.topological, 1);
  const ErrorSample headland_est = computeError(map, idx(map, "H6"), Eigen::Vector2d(6.0, -3.2));
  EXPECT_FALSE(headland_est.lane_applicable);
  EXPECT_TRUE(headland_est.in_true_lane);  // both outside every lane (display only)
  EXPECT_EQ(headland_est.topological, 2);
  // Share over lane samples only: one right, one wrong, two headland samples ignored.
  std::vector<ErrorSample> run = {in_lane_est, headland_est,
                                  computeError(map, idx(map, "r1_1"), Eigen::Vector2d(1.5, 3.0)),
                                  computeError(map, idx(map, "r2_1"), Eigen::Vector2d(1.5, 3.0))};
  const RunMetrics r = summariseRun(run);
  EXPECT_EQ(r.lane_samples, 2u);
  EXPECT_DOUBLE_EQ(r.right_lane_share, 0.5);
  // Only headland samples: share undefined.
  EXPECT_TRUE(std::isnan(summariseRun({in_lane_est}).right_lane_share));
}

TEST(EvalMetrics, InvalidNodeThrows) {
  const auto map = polytunnel();
  EXPECT_THROW(computeError(map, topology::kInvalidNode, Eigen::Vector2d::Zero()), std::out_of_range);
}

TEST(EvalMetrics, UnreachableExcludedFromHops) {
  std::vector<topology::Node> nodes(3);
  nodes[0].name = "a";
  nodes[1].name = "b";
  nodes[1].position = Eigen::Vector3d(1, 0, 0);
  nodes[2].name = "island";
  nodes[2].position = Eigen::Vector3d(10, 0, 0);
  const auto map = topology::TopologicalMap::build("m", nodes, {{"ab", "a", "b", "move_base"}});
  const ErrorSample s = computeError(map, 0, Eigen::Vector2d(10, 0));
  EXPECT_EQ(s.topological, -1);
  const ErrorSample t = computeError(map, 0, Eigen::Vector2d(1, 0));
  const RunMetrics r = summariseRun({s, t});
  EXPECT_EQ(r.unreachable, 1u);
  EXPECT_DOUBLE_EQ(r.topological_mean, 1.0);
  EXPECT_DOUBLE_EQ(r.euclidean_mean, 5.5);
}

TEST(EvalMetrics, AggregationOverRuns) {
  auto sample = [](double eu, int topo, bool lane_ok) {
    ErrorSample s;
    s.euclidean = eu;
    s.topological = topo;
    s.lane_applicable = true;
    s.in_true_lane = lane_ok;
    return s;
  };
  // run 1: eu {1, 3} -> 2, topo {0, 2} -> 1, share 0.5; run 2: eu {4, 4} -> 4, topo {3, 3} -> 3, share 1.
  const std::vector<std::vector<ErrorSample>> runs = {{sample(1, 0, true), sample(3, 2, false)},
                                                      {sample(4, 3, true), sample(4, 3, true)}};
  const MethodSummary m = summariseMethod("x", runs);
  EXPECT_EQ(m.runs, 2u);
  EXPECT_DOUBLE_EQ(m.euclidean_mean, 3.0);
  EXPECT_NEAR(m.euclidean_std, std::sqrt(2.0), 1e-12);  // sample std of {2, 4}
  EXPECT_DOUBLE_EQ(m.topological_mean, 2.0);
  EXPECT_NEAR(m.topological_std, std::sqrt(2.0), 1e-12);
  EXPECT_DOUBLE_EQ(m.right_lane_share, 0.75);
  EXPECT_NEAR(m.right_lane_share_std, std::sqrt(0.125), 1e-12);  // sample std of {0.5, 1}
  // pooled: eu {1,3,4,4} mean 3, population var (4+0+1+1)/4 = 1.5
  EXPECT_NEAR(m.euclidean_pooled_std, std::sqrt(1.5), 1e-12);
  const MethodSummary one = summariseMethod("y", {runs[0]});
  EXPECT_DOUBLE_EQ(one.euclidean_std, 0.0);
}

TEST(EvalReport, SummaryCsvHeaderAndUnavailableRow) {
  MethodSummary a;
  a.method = "khan_connected";
  a.runs = 10;
  a.euclidean_mean = 1.5;
  a.euclidean_std = 0.25;
  a.topological_mean = 3;
  a.topological_std = 1;
  a.right_lane_share = 0.8;
  a.right_lane_share_std = 0.05;
  const std::string csv = summaryCsv({a, unavailableMethod("nbs", "no nbs library")});
  std::istringstream in(csv);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line,
            "method,runs,euclidean_mean,euclidean_std,topological_mean,topological_std,right_lane_share,"
            "right_lane_share_std");
  std::getline(in, line);
  EXPECT_EQ(line, "khan_connected,10,1.5000,0.2500,3.0000,1.0000,0.8000,0.0500");
  std::getline(in, line);
  EXPECT_EQ(line, "nbs,0,unavailable,unavailable,unavailable,unavailable,unavailable,unavailable");
  const std::string md = summaryMarkdown("t", {a, unavailableMethod("nbs", "no nbs library")});
  EXPECT_NE(md.find("| khan_connected | 10 | 1.50 (0.25)"), std::string::npos);
  EXPECT_NE(md.find("unavailable: no nbs library"), std::string::npos);
}

TEST(EvalReport, RunCsvAndPlot) {
  const auto map = polytunnel();
  std::vector<ErrorSample> run;
  for (int i = 0; i < 20; ++i)
    run.push_back(computeError(map, idx(map, "r2_2"), Eigen::Vector2d(3.0, 0.5 * i), i, "p"));
  const std::string csv_path = testing::TempDir() + "eval_run.csv";
  writeRunCsv(csv_path, map, run);
  std::ifstream f(csv_path);
  std::string header, first;
  std::getline(f, header);
  std::getline(f, first);
  EXPECT_EQ(header.rfind("stamp,picker_id,estimated_node,true_node", 0), 0u);
  EXPECT_EQ(first, "0.000,p,r2_2,r2_0,3.000,0.000,6.0000,2,1,1");
  const ErrorSeries series = binErrors("m", {run}, 0.0, 5.0);
  ASSERT_EQ(series.t.size(), 4u);
  EXPECT_DOUBLE_EQ(series.t[0], 2.5);
  // first bin: truth y = 0, 0.5, 1, 1.5, 2 -> errors 6, 5.5, 5, 4.5, 4 -> mean 5
  EXPECT_NEAR(series.euclidean[0], 5.0, 1e-12);
  const std::string png = testing::TempDir() + "eval_plot.png";
  plotErrors(png, {series, binErrors("n", {run}, 0.0, 2.0)}, 640, 480);
  const cv::Mat img = cv::imread(png);
  ASSERT_FALSE(img.empty());
  EXPECT_EQ(img.cols, 640);
  EXPECT_EQ(img.rows, 480);
  EXPECT_THROW(plotErrors("/nonexistent_dir/x.png", {series}), std::runtime_error);
  std::remove(csv_path.c_str());
  std::remove(png.c_str());
}

TEST(EvalMetrics, RealRiseholmeMapLanes) {
  const auto map = topology::loadMap(std::string(PL_PACKAGE_DIR) + "/config/maps/riseholme.tmap2");
  ASSERT_GT(map.numLanes(), 0u);
  // An estimate on the true node of any lane node: zero error, in its lane.
  const topology::NodeIndex n = map.laneNodes(0).front();
  const ErrorSample s = computeError(map, n, map.position2d(n));
  EXPECT_EQ(s.topological, 0);
  EXPECT_TRUE(s.lane_applicable);
  EXPECT_TRUE(s.in_true_lane);
}

TEST(EvalReport, ErrorTableRows) {
  const auto map = polytunnel();
  std::vector<ErrorSample> a = {computeError(map, idx(map, "r2_2"), Eigen::Vector2d(3.0, 6.0)),
                                computeError(map, idx(map, "r2_2"), Eigen::Vector2d(3.0, 9.0))};
  const std::string t = errorTable({{"picker_1", a}, {"picker_2", {}}});
  std::istringstream in(t);
  std::string header, p1, p2, all;
  std::getline(in, header);
  std::getline(in, p1);
  std::getline(in, p2);
  std::getline(in, all);
  EXPECT_NE(header.find("eucl[m]"), std::string::npos);
  std::istringstream r(p1);
  std::string id;
  std::size_t n;
  double eu, eu_sd, topo, topo_sd, share;
  r >> id >> n >> eu >> eu_sd >> topo >> topo_sd >> share;
  EXPECT_EQ(id, "picker_1");
  EXPECT_EQ(n, 2u);
  EXPECT_DOUBLE_EQ(eu, 1.5);    // errors 0 and 3
  EXPECT_DOUBLE_EQ(topo, 0.5);  // hops 0 and 1
  EXPECT_DOUBLE_EQ(share, 1.0);
  EXPECT_EQ(all.rfind("all", 0), 0u);
}
