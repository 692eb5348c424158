// Farm simulator core: lane layout and tours on real and synthetic maps, picker motion (graph, lanes,
// reversal rate, lane switching), the GNSS error model against Table I, blackouts, the datum projection, the
// laser ray cast against analytic ranges, RFID / UWB / camera statistics, robots, determinism, config.
#include <gtest/gtest.h>

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <numeric>
#include <set>

#include "legacy_tmap.h"
#include "picker_localisation/sim/farm_simulator.h"
#include "picker_localisation/topology/map_io.h"
#include "picker_localisation/topology/synthetic_map.h"

using namespace picker_localisation;
using namespace picker_localisation::sim;
using topology::NodeIndex;

namespace {
const std::string kTmap2 = std::string(PL_PACKAGE_DIR) + "/config/maps/riseholme.tmap2";
const std::string kLegacy = picker_localisation::test::legacyRiseholmePath();  // one-way edges, chain lanes

topology::TopologicalMap polytunnel(std::size_t lanes = 6, std::size_t per_lane = 8) {
  topology::PolytunnelSpec spec;
  spec.lanes = lanes;
  spec.nodes_per_lane = per_lane;
  return topology::makePolytunnelMap(spec);
}

// A 4 x 4 grid: every inner node is a junction, no tags, no row_traversal: a map without lanes.
topology::TopologicalMap gridMap() {
  std::vector<topology::Node> nodes;
  std::vector<topology::EdgeSpec> edges;
  auto name = [](int i, int j) { return "g" + std::to_string(i) + "_" + std::to_string(j); };
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      topology::Node n;
      n.name = name(i, j);
      n.position = {3.0 * i, 3.0 * j, 0.0};
      nodes.push_back(n);
      if (i + 1 < 4) edges.push_back({"", name(i, j), name(i + 1, j), "move_base"});
      if (j + 1 < 4) edges.push_back({"", name(i, j), name(i, j + 1), "move_base"});
    }
  return topology::TopologicalMap::build("grid", nodes, edges);
}

double distanceToSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double t = ab.squaredNorm() > 0 ? std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

double mean(const std::vector<double>& v) {
  return std::accumulate(v.begin(), v.end(), 0.0) / v.size();
}
double stddev(const std::vector<double>& v) {
  const double m = mean(v);
  double s = 0.0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / (v.size() - 1));
}

SimConfig quietConfig(std::uint64_t seed = 7) {
  SimConfig c;
  c.seed = seed;
  return c;
}
}  // namespace

// ---------------------------------------------------------------------------------------------------------
TEST(LaneLayout, SyntheticPolytunnelOrderAndEnds) {
  const auto map = polytunnel(6, 8);
  LaneLayout layout(map);
  ASSERT_EQ(layout.lanes().size(), 6u);
  EXPECT_NEAR(std::abs(layout.alongAxis().y()), 1.0, 1e-9);  // lanes run along y
  EXPECT_NEAR(layout.laneSpacing(), 1.5, 1e-9);
  double prev_across = -1e9;
  for (const auto& lane : layout.lanes()) {
    EXPECT_TRUE(lane.was_chain);
    ASSERT_EQ(lane.nodes.size(), 8u);
    const double across = layout.acrossAxis().dot(lane.centroid);
    EXPECT_GT(across, prev_across);
    prev_across = across;
    // Ordered entry -> far along the farm axis, consecutive nodes adjacent.
    for (std::size_t k = 0; k + 1 < lane.nodes.size(); ++k) {
      EXPECT_TRUE(map.connected(lane.nodes[k], lane.nodes[k + 1]));
      EXPECT_LT(layout.alongAxis().dot(map.position2d(lane.nodes[k])),
                layout.alongAxis().dot(map.position2d(lane.nodes[k + 1])));
    }
  }
}

TEST(LaneLayout, RiseholmeMapsHaveOrderedLanes) {
  for (const auto& path : {kTmap2, kLegacy}) {
    const auto map = topology::loadMap(path);
    LaneLayout layout(map);
    ASSERT_EQ(layout.lanes().size(), map.numLanes()) << path;
    ASSERT_GE(layout.lanes().size(), 2u) << path;
    for (const auto& lane : layout.lanes()) {
      for (NodeIndex n : lane.nodes) EXPECT_EQ(map.lane(n), lane.lane);
      EXPECT_LE(layout.alongAxis().dot(map.position2d(lane.entry_end())),
                layout.alongAxis().dot(map.position2d(lane.far_end())));
    }
    EXPECT_GT(layout.laneSpacing(), 0.5) << path;
    EXPECT_LT(layout.laneSpacing(), 10.0) << path;
  }
}

// A tour is a closed walk on the graph: consecutive nodes (and the last and the first) are adjacent.
void expectClosedWalk(const topology::TopologicalMap& map, const std::vector<NodeIndex>& tour) {
  for (std::size_t k = 0; k < tour.size(); ++k)
    EXPECT_TRUE(map.connected(tour[k], tour[(k + 1) % tour.size()])) << k;
}

// The layout order of each lane a tour enters, in the order entered.
std::vector<int> laneSequence(const topology::TopologicalMap& map, const LaneLayout& layout,
                              const std::vector<NodeIndex>& tour) {
  std::vector<int> sequence;
  for (NodeIndex n : tour) {
    const int o = layout.orderOf(map.lane(n));
    if (o >= 0 && (sequence.empty() || sequence.back() != o)) sequence.push_back(o);
  }
  return sequence;
}

// The tour's nodes that lie in `lane`, in tour order.
std::vector<NodeIndex> nodesInLane(const topology::TopologicalMap& map, const std::vector<NodeIndex>& tour,
                                   topology::LaneIndex lane) {
  std::vector<NodeIndex> seen;
  for (NodeIndex n : tour)
    if (map.lane(n) == lane) seen.push_back(n);
  return seen;
}

TEST(LaneTour, SerpentineOnPolytunnel) {
  const auto map = polytunnel(6, 8);
  LaneLayout layout(map);
  const auto tour = buildLaneTour(map, layout, 0);
  expectClosedWalk(map, tour);
  // Lanes in adjacency order, alternating direction: even lanes entry->far, odd lanes far->entry.
  EXPECT_EQ(laneSequence(map, layout, tour), (std::vector<int>{0, 1, 2, 3, 4, 5}));
  for (const auto& lane : layout.lanes()) {
    const int o = layout.orderOf(lane.lane);
    std::vector<NodeIndex> expected = lane.nodes;
    if (o % 2 == 1) std::reverse(expected.begin(), expected.end());
    EXPECT_EQ(nodesInLane(map, tour, lane.lane), expected) << "lane " << o;
  }
  // Starting elsewhere gives the same cycle rotated.
  const auto tour2 = buildLaneTour(map, layout, 2);
  EXPECT_EQ(map.lane(tour2.front()), layout.lanes()[2].lane);
  EXPECT_EQ(tour2.front(), layout.lanes()[2].entry_end());
}

TEST(LaneTour, SkipOneWalksEveryOtherLane) {
  const auto map = polytunnel(8, 8);
  LaneLayout layout(map);
  const auto tour = buildLaneTour(map, layout, 0, {}, LaneOrder::kSkipOne);
  expectClosedWalk(map, tour);
  // Lanes 0, 2, 4, 6 walked end to end in alternating directions; the others at most passed at an end.
  std::vector<int> walked;
  for (const auto& lane : layout.lanes()) {
    const std::size_t inside = nodesInLane(map, tour, lane.lane).size();
    if (inside == lane.nodes.size()) walked.push_back(layout.orderOf(lane.lane));
    EXPECT_TRUE(inside == lane.nodes.size() || inside < lane.nodes.size() / 2)
        << layout.orderOf(lane.lane) << ": " << inside;
  }
  EXPECT_EQ(walked, (std::vector<int>{0, 2, 4, 6}));
  EXPECT_EQ(tour.front(), layout.lanes()[0].entry_end());
  const auto& lane2 = layout.lanes()[2].nodes;
  EXPECT_NE(std::find(tour.begin(), tour.end(), lane2.back()), tour.end());
  // The second lane walked (lane 2) is walked far end first.
  const auto far = std::find(tour.begin(), tour.end(), lane2.back());
  const auto entry = std::find(tour.begin(), tour.end(), lane2.front());
  EXPECT_LT(far - tour.begin(), entry - tour.begin());
}

TEST(LaneTour, OutAndBackReturnsByTheSameLane) {
  const auto map = polytunnel(4, 8);
  LaneLayout layout(map);
  const auto tour = buildLaneTour(map, layout, 0, {}, LaneOrder::kOutAndBack);
  expectClosedWalk(map, tour);
  EXPECT_EQ(laneSequence(map, layout, tour), (std::vector<int>{0, 1, 2, 3}));
  for (const auto& lane : layout.lanes()) {
    std::vector<NodeIndex> expected = lane.nodes;
    expected.insert(expected.end(), lane.nodes.rbegin() + 1, lane.nodes.rend());
    EXPECT_EQ(nodesInLane(map, tour, lane.lane), expected) << "lane " << layout.orderOf(lane.lane);
  }
  EXPECT_EQ(parseLaneOrder("out_and_back"), LaneOrder::kOutAndBack);
  EXPECT_STREQ(toString(LaneOrder::kSkipOne), "skip_one");
  EXPECT_THROW(parseLaneOrder("zigzag"), std::invalid_argument);
}

TEST(PickerMotion, LongStopsHoldThePickerForMinutes) {
  const auto map = polytunnel(2, 20);
  LaneLayout layout(map);
  PickerMotionParams params;
  params.p_reverse = 0.0;
  params.long_stop_probability = 0.2;
  params.long_stop_mean = 120.0;
  SimulatedPicker picker(map, buildLaneTour(map, layout, 0), params, 5);
  double stopped = 0.0, longest = 0.0, run = 0.0;
  for (int k = 0; k < 36000; ++k) {  // one hour at 0.1 s
    picker.step(0.1);
    const bool still = picker.state().dwelling;
    run = still ? run + 0.1 : 0.0;
    stopped += still ? 0.1 : 0.0;
    longest = std::max(longest, run);
  }
  // A lane node every ~6 s of walking, a fifth of them a 2 min stop: stopped most of the hour.
  EXPECT_GT(stopped, 1800.0);
  EXPECT_GT(longest, 120.0);
  PickerMotionParams walking = params;
  walking.long_stop_probability = 0.0;
  SimulatedPicker other(map, buildLaneTour(map, layout, 0), walking, 5);
  for (int k = 0; k < 3600; ++k) {
    other.step(0.1);
    EXPECT_FALSE(other.state().dwelling);
  }
}

TEST(LaneTour, MapWithoutLanesUsesWaypoints) {
  const auto map = gridMap();
  EXPECT_EQ(map.numLanes(), 0u);
  LaneLayout layout(map);
  EXPECT_TRUE(layout.empty());
  EXPECT_THROW(buildLaneTour(map, layout, 0), std::invalid_argument);
  const auto tour = buildLaneTour(map, layout, 0, {0, 15, 3});
  ASSERT_GE(tour.size(), 2u);
  expectClosedWalk(map, tour);
  EXPECT_EQ(tour.front(), 0u);
  EXPECT_NE(std::find(tour.begin(), tour.end(), 15u), tour.end());
}

// ---------------------------------------------------------------------------------------------------------
// Checks the picker is on one edge of its tour, in walking direction; returns true when inside a lane.
void expectOnTour(const topology::TopologicalMap& map, const SimulatedPicker& p) {
  const auto& s = p.state();
  ASSERT_TRUE(map.connected(s.from, s.to));
  EXPECT_LT(distanceToSegment(p.pose().position(), map.position2d(s.from), map.position2d(s.to)), 1e-6);
}

TEST(PickerMotion, StaysOnTheGraphAndInLanes) {
  const auto map = polytunnel(6, 8);
  LaneLayout layout(map);
  PickerMotionParams params;
  SimulatedPicker picker(map, buildLaneTour(map, layout, 0), params, 42);
  std::set<std::pair<NodeIndex, NodeIndex>> tour_edges;
  const auto& tour = picker.tour();
  for (std::size_t k = 0; k < tour.size(); ++k) {
    tour_edges.insert({tour[k], tour[(k + 1) % tour.size()]});
    tour_edges.insert({tour[(k + 1) % tour.size()], tour[k]});
  }
  int in_lane = 0, steps = 0;
  for (int k = 0; k < 20000; ++k) {
    picker.step(0.1);
    expectOnTour(map, picker);
    EXPECT_TRUE(tour_edges.count({picker.state().from, picker.state().to}));
    if (map.lane(picker.state().nearest_node) != topology::kNoLane) ++in_lane;
    ++steps;
  }
  EXPECT_NEAR(picker.time(), 2000.0, 1e-6);
  // Lanes are 21 m and the headland hops 3 m + 1.5 m: most of the time is spent in lanes.
  EXPECT_GT(in_lane, steps * 0.7);
}

// Runs five pickers for `seconds` each: decisions, reversals, reversed time share, reversal durations.
struct ReversalStats {
  std::size_t decisions = 0, reversals = 0, arrivals = 0;
  double reversed_share = 0.0;
  std::vector<double> durations;
};
ReversalStats runReversals(const PickerMotionParams& params, double seconds) {
  const auto map = polytunnel(6, 8);
  LaneLayout layout(map);
  ReversalStats st;
  double reversed_time = 0.0, total = 0.0;
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    SimulatedPicker picker(map, buildLaneTour(map, layout, 0), params, seed);
    bool was = false;
    double since = 0.0;
    for (int k = 0; k < static_cast<int>(seconds * 10); ++k) {
      picker.step(0.1);
      const bool rev = picker.state().reversed;
      if (rev) reversed_time += 0.1;
      total += 0.1;
      if (rev && !was) since = picker.time();
      if (!rev && was) st.durations.push_back(picker.time() - since);
      was = rev;
    }
    st.decisions += picker.reversalDecisions();
    st.reversals += picker.reversalsStarted();
    st.arrivals += picker.forwardArrivals();
  }
  st.reversed_share = reversed_time / total;
  return st;
}

TEST(PickerMotion, ReversesWithTheConfiguredRate) {
  PickerMotionParams params;  // p_reverse 0.1, t_reverse 60 s, one decision per 60 s of forward walking
  const ReversalStats st = runReversals(params, 40000.0);
  // Decisions: one per reverse_step of forward time.
  EXPECT_NEAR(static_cast<double>(st.decisions), 5 * 40000.0 * (1.0 - st.reversed_share) / 60.0, 5.0);
  ASSERT_GT(st.decisions, 2000u);
  const double rate = static_cast<double>(st.reversals) / st.decisions;
  EXPECT_NEAR(rate, 0.1, 4.0 * std::sqrt(0.1 * 0.9 / st.decisions));
  // Share of time reversed: p t_rev / (reverse_step + p t_rev) = 6 / 66.
  EXPECT_NEAR(st.reversed_share, 6.0 / 66.0, 0.015);
  ASSERT_GT(st.durations.size(), 100u);
  for (double d : st.durations) EXPECT_NEAR(d, 60.0, 0.11);  // to the step resolution

  // Per-arrival decisions (reverse_step 0): the rate holds per forward node arrival.
  params.reverse_step = 0.0;
  const ReversalStats pa = runReversals(params, 4000.0);
  EXPECT_EQ(pa.decisions, pa.arrivals);
  ASSERT_GT(pa.arrivals, 1000u);
  EXPECT_NEAR(static_cast<double>(pa.reversals) / pa.arrivals, 0.1, 4.0 * std::sqrt(0.09 / pa.arrivals));
  for (double d : pa.durations) EXPECT_NEAR(d, 60.0, 0.11);
}

TEST(PickerMotion, MakesProgressThroughTheLanes) {
  // With the default reversal model a picker walks through many lanes in an hour (net forward progress).
  const auto map = polytunnel(6, 8);
  LaneLayout layout(map);
  SimulatedPicker picker(map, buildLaneTour(map, layout, 0), PickerMotionParams(), 21);
  picker.step(3600.0);
  EXPECT_GT(picker.lanesEntered(), 20u);
}

TEST(PickerMotion, SwitchesToTheAdjacentLaneAtLaneEnds) {
  const auto map = polytunnel(6, 8);
  LaneLayout layout(map);
  PickerMotionParams params;
  params.p_reverse = 0.0;
  SimulatedPicker picker(map, buildLaneTour(map, layout, 0), params, 3);
  std::vector<int> lanes;
  topology::LaneIndex current = map.lane(picker.state().from);
  lanes.push_back(layout.orderOf(current));
  NodeIndex last_lane_node = picker.state().from;
  for (int k = 0; k < 30000; ++k) {
    picker.step(0.1);
    const NodeIndex n = picker.state().from;
    const auto l = map.lane(n);
    if (l == topology::kNoLane) continue;
    if (l != current) {
      // Entered a new lane: from one of its ends, having left the previous lane at one of its ends.
      const auto& info = layout.lanes()[static_cast<std::size_t>(layout.orderOf(l))];
      EXPECT_TRUE(n == info.entry_end() || n == info.far_end());
      const auto& prev = layout.lanes()[static_cast<std::size_t>(layout.orderOf(current))];
      EXPECT_TRUE(last_lane_node == prev.entry_end() || last_lane_node == prev.far_end());
      current = l;
      lanes.push_back(layout.orderOf(l));
    }
    last_lane_node = n;
  }
  ASSERT_GT(lanes.size(), 8u);
  for (std::size_t k = 1; k < lanes.size(); ++k) EXPECT_EQ(lanes[k], (lanes[k - 1] + 1) % 6) << k;
  EXPECT_EQ(picker.reversalsStarted(), 0u);
}

TEST(PickerMotion, SpeedsFollowTheTruncatedNormal) {
  const auto map = polytunnel(4, 6);
  LaneLayout layout(map);
  PickerMotionParams params;
  std::vector<double> speeds;
  for (std::uint64_t seed = 0; seed < 2000; ++seed) {
    SimulatedPicker p(map, buildLaneTour(map, layout, 0), params, seed);
    speeds.push_back(p.state().speed);
    EXPECT_GE(p.state().speed, params.speed_min);
    EXPECT_LE(p.state().speed, params.speed_max);
  }
  EXPECT_NEAR(mean(speeds), params.speed_mean, 0.01);
  EXPECT_NEAR(stddev(speeds), params.speed_std, 0.01);  // truncation at +-3 sigma barely changes the std
}

TEST(PickerMotion, LegsAreTwoCirclesAroundThePicker) {
  const auto map = polytunnel(4, 6);
  LaneLayout layout(map);
  PickerMotionParams params;
  SimulatedPicker p(map, buildLaneTour(map, layout, 0), params, 1);
  double max_sep = 0.0;
  for (int k = 0; k < 50; ++k) {
    p.step(0.05);
    const auto legs = p.legCentres();
    const Eigen::Vector2d c = p.pose().position();
    EXPECT_NEAR(((legs[0] + legs[1]) / 2 - c).norm(), 0.0, 1e-9);
    max_sep = std::max(max_sep, (legs[0] - legs[1]).norm());
  }
  EXPECT_GT(max_sep, params.leg_spread + 0.05);  // the legs swing while walking
}

// ---------------------------------------------------------------------------------------------------------
TEST(GnssModel, OffsetsAreUniformZeroToThreePointFive) {
  GnssNoiseParams params;
  std::vector<double> xs, ys;
  for (std::uint64_t s = 0; s < 4000; ++s) {
    GnssErrorModel m(params, s);
    EXPECT_GE(m.offset().x(), 0.0);
    EXPECT_LE(m.offset().x(), 3.5);
    EXPECT_GE(m.offset().y(), 0.0);
    EXPECT_LE(m.offset().y(), 3.5);
    xs.push_back(m.offset().x());
    ys.push_back(m.offset().y());
  }
  EXPECT_NEAR(mean(xs), 1.75, 0.05);
  EXPECT_NEAR(stddev(xs), 3.5 / std::sqrt(12.0), 0.04);
  EXPECT_NEAR(mean(ys), 1.75, 0.05);
}

TEST(GnssModel, WhiteNoiseStd) {
  GnssNoiseParams params;
  params.drift_std = 0.0;
  params.blackout_mean_interval = 0.0;  // no blackouts
  GnssErrorModel m(params, 5);
  std::vector<double> ex, ey;
  for (int k = 1; k <= 20000; ++k) {
    const auto e = m.sample(k * 1.0);
    ASSERT_TRUE(e);
    ex.push_back(e->x() - m.offset().x());
    ey.push_back(e->y() - m.offset().y());
  }
  EXPECT_NEAR(mean(ex), 0.0, 0.005);
  EXPECT_NEAR(stddev(ex), 0.1, 0.003);
  EXPECT_NEAR(stddev(ey), 0.1, 0.003);
}

TEST(GnssModel, DriftIsStationaryWithStdTwoPointFive) {
  GnssNoiseParams params;
  params.white_std = 0.0;
  params.blackout_mean_interval = 0.0;
  std::vector<double> d0, d1, dlag;
  for (std::uint64_t s = 0; s < 3000; ++s) {
    GnssErrorModel m(params, 100 + s);
    d0.push_back(m.drift().x());
    m.advanceTo(1000.0);
    const auto e = m.sample(1000.0);
    ASSERT_TRUE(e);
    d1.push_back(e->x() - m.offset().x());
    m.advanceTo(1000.0 + params.drift_tau);
    dlag.push_back(m.drift().x());
  }
  EXPECT_NEAR(mean(d0), 0.0, 0.15);
  EXPECT_NEAR(stddev(d0), 2.5, 0.1);
  EXPECT_NEAR(mean(d1), 0.0, 0.15);
  EXPECT_NEAR(stddev(d1), 2.5, 0.1);
  // Gauss-Markov: correlation exp(-1) after one correlation time.
  double cov = 0.0;
  for (std::size_t k = 0; k < d1.size(); ++k) cov += d1[k] * dlag[k];
  cov /= d1.size();
  EXPECT_NEAR(cov / (2.5 * 2.5), std::exp(-1.0), 0.05);
}

TEST(GnssModel, BlackoutsLastThirtyToSixtySeconds) {
  GnssNoiseParams params;
  GnssErrorModel m(params, 9);
  double off_time = 0.0;
  const int n = 400000;
  for (int k = 1; k <= n; ++k) {
    if (!m.sample(k * 1.0)) off_time += 1.0;
  }
  const auto& log = m.blackouts();
  ASSERT_GT(log.size(), 400u);
  std::vector<double> durations;
  for (const auto& b : log) {
    const double d = b.second - b.first;
    EXPECT_GE(d, 30.0);
    EXPECT_LE(d, 60.0);
    durations.push_back(d);
  }
  EXPECT_NEAR(mean(durations), 45.0, 1.5);
  // Onsets: one per blackout_mean_interval of non-blackout time -> share of time off = 45 / (600 + 45).
  EXPECT_NEAR(off_time / n, 45.0 / 645.0, 0.01);
  EXPECT_NEAR((n - off_time) / log.size(), 600.0, 60.0);
}

TEST(GnssModel, DriftRedrawnAfterABlackoutWhenAsked) {
  // With a correlation time of a day the drift barely moves by itself: a jump at the end of a blackout is the
  // redraw. Without the option the drift continues where it was.
  GnssNoiseParams params;
  params.offset_max = 0.0;
  params.white_std = 0.0;
  params.drift_tau = 86400.0;
  params.blackout_mean_interval = 300.0;
  for (bool redraw : {false, true}) {
    params.redraw_after_blackout = redraw;
    GnssErrorModel m(params, 21);
    std::optional<Eigen::Vector2d> before, last;
    double largest_jump = 0.0;
    for (int k = 1; k <= 20000; ++k) {
      const auto e = m.sample(k * 1.0);
      if (!e) {
        if (last) before = last;
        last.reset();
        continue;
      }
      if (!last && before) largest_jump = std::max(largest_jump, (*e - *before).norm());
      last = e;
    }
    ASSERT_GT(m.blackouts().size(), 10u);
    if (redraw)
      EXPECT_GT(largest_jump, 2.5);  // |N(0, 2.5^2 I) - N(0, 2.5^2 I)| over > 10 blackouts
    else
      EXPECT_LT(largest_jump, 0.6);  // 60 s of a one-day process: ~0.1 m per axis
  }
}

TEST(GnssModel, FixesGoThroughTheDatum) {
  core::DatumConfig config = riseholmeDatum();
  config.heading = 30.0 * M_PI / 180.0;
  const core::GeodeticDatum datum(config);
  GnssNoiseParams params;
  GnssErrorModel m(params, 11);
  int fixes = 0, no_fix = 0;
  for (int k = 1; k <= 3000; ++k) {
    const Eigen::Vector2d truth(10.0 + 0.01 * k, -5.0);
    const auto fix = makeGnssFix(m, datum, params, k, truth);
    ASSERT_TRUE(fix);
    if (fix->status == -1) {
      EXPECT_TRUE(std::isnan(fix->latitude));
      ++no_fix;
      continue;
    }
    ++fixes;
    const Eigen::Vector2d back = datum.toMap(fix->latitude, fix->longitude, fix->altitude);
    EXPECT_NEAR((back - (truth + fix->error)).norm(), 0.0, 1e-6);
    EXPECT_NEAR(fix->altitude, config.altitude + params.antenna_height, 1e-3);
    EXPECT_DOUBLE_EQ(fix->position_covariance[0], params.reported_std * params.reported_std);
  }
  EXPECT_GT(fixes, 0);
  // Heading 90 deg: map x points North (a degree of latitude is ~111.2 km here).
  config.heading = M_PI / 2.0;
  const core::GeodeticDatum north(config);
  double lat, lon, alt;
  north.toGeodetic({100.0, 0.0}, 0.0, lat, lon, alt);
  EXPECT_NEAR(lon, config.longitude, 1e-9);
  EXPECT_NEAR((lat - config.latitude) * 111200.0, 100.0, 0.5);
}

// The `datum:` section of config/sim.yaml has config/datum.yaml's keys (core::DatumConfig), unknown keys
// refused.
TEST(GnssModel, SimConfigDatumSectionKeys) {
  SimConfig c;
  EXPECT_NEAR(c.datum.latitude, 53.268, 1e-9);  // default: Riseholme, as config/datum.yaml
  applySimConfigYaml(
      YAML::Load("datum: {latitude: 53.1, longitude: -0.6, altitude: 12.0, heading_deg: 15.0}"), c);
  EXPECT_DOUBLE_EQ(c.datum.latitude, 53.1);
  EXPECT_DOUBLE_EQ(c.datum.altitude, 12.0);
  EXPECT_NEAR(c.datum.heading, 15.0 * M_PI / 180.0, 1e-12);
  applySimConfigYaml(
      YAML::Load("datum: {type: utm, utm_zone: 30, utm_easting: 664000, utm_northing: 5905000}"), c);
  EXPECT_EQ(c.datum.kind, core::DatumConfig::Kind::kUtm);
  EXPECT_THROW(applySimConfigYaml(YAML::Load("datum: {latitude: 53.1, longitude: -0.6, headng_deg: 1}"), c),
               std::runtime_error);
  EXPECT_THROW(applySimConfigYaml(YAML::Load("datum: {longitude: 1.0}"), c), std::runtime_error);
  EXPECT_THROW(applySimConfigYaml(YAML::Load("datum: {latitude: 95.0, longitude: 1.0}"), c),
               std::runtime_error);
}

// ---------------------------------------------------------------------------------------------------------
TEST(LaserModel, RayHitsALegCircleAtTheAnalyticRange) {
  LaserScene scene;
  scene.circles.push_back({{5.0, 0.0}, 0.06});
  scene.circles.push_back({{0.0, 3.0}, 0.1});
  scene.segments.push_back({{-4.0, -1.0}, {-4.0, 1.0}});
  LaserParams params;
  params.range_noise_std = 0.0;
  params.angle_min = -M_PI;
  params.angle_max = M_PI;
  params.angle_increment = M_PI / 180.0 / 4.0;
  std::mt19937_64 rng(1);
  const Pose2D sensor{0.0, 0.0, 0.0};
  const LaserScanWithTruth scan = castLaser(scene, sensor, params, 1.0, rng);
  auto beam = [&](double angle) {
    return static_cast<std::size_t>(std::lround((angle - scan.angle_min) / scan.angle_increment));
  };
  EXPECT_NEAR(scan.ranges[beam(0.0)], 5.0 - 0.06, 1e-5);
  EXPECT_NEAR(scan.ranges[beam(M_PI / 2)], 3.0 - 0.1, 1e-5);
  EXPECT_NEAR(scan.ranges[beam(M_PI)], 4.0, 1e-5);
  // Off-centre beam: r = d cos(t) - sqrt(R^2 - d^2 sin^2(t)).
  const double t = 2.0 * params.angle_increment;
  const double expected = 5.0 * std::cos(t) - std::sqrt(0.06 * 0.06 - 25.0 * std::sin(t) * std::sin(t));
  EXPECT_NEAR(scan.ranges[beam(t)], expected, 1e-5);
  // A beam through empty space has no return.
  EXPECT_TRUE(std::isinf(scan.ranges[beam(-M_PI / 4)]));
  EXPECT_GT(scan.ranges[beam(-M_PI / 4)], 0.0);
  // A rotated, translated sensor sees the same leg at the same range.
  const Pose2D moved{5.0, -2.0, M_PI / 2};
  const LaserScanWithTruth s2 = castLaser(scene, moved, params, 1.0, rng);
  EXPECT_NEAR(s2.ranges[beam(0.0)], 2.0 - 0.06, 1e-5);
}

TEST(LaserModel, BeamWindowsMatchTestingEveryBeam) {
  // The ray cast only tests the beams inside each obstacle's angular extent; it must equal testing every beam
  // against every obstacle, for random scenes and sensor poses (including wrap-around at +-pi).
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> u(-8.0, 8.0), ang(-M_PI, M_PI), rad(0.02, 0.5);
  LaserParams params;
  params.range_noise_std = 0.0;
  for (int trial = 0; trial < 40; ++trial) {
    LaserScene scene;
    for (int k = 0; k < 30; ++k) scene.circles.push_back({{u(rng), u(rng)}, rad(rng)});
    for (int k = 0; k < 6; ++k) scene.segments.push_back({{u(rng), u(rng)}, {u(rng), u(rng)}});
    if (trial % 2) {
      params.angle_min = -M_PI;
      params.angle_max = M_PI;
    } else {
      params.angle_min = -2.356194;
      params.angle_max = 2.356194;
    }
    const Pose2D pose{u(rng) * 0.2, u(rng) * 0.2, ang(rng)};
    const LaserScanWithTruth scan = castLaser(scene, pose, params, 0.0, rng);
    for (std::size_t i = 0; i < scan.ranges.size(); ++i) {
      const double a = pose.yaw + scan.angle_min + i * scan.angle_increment;
      const Eigen::Vector2d d(std::cos(a), std::sin(a));
      double r = std::numeric_limits<double>::infinity();
      for (const auto& c : scene.circles) r = std::min(r, rayCircle(pose.position(), d, c));
      for (const auto& sg : scene.segments) r = std::min(r, raySegment(pose.position(), d, sg));
      if (r < params.range_min) continue;  // -inf (too close) or inside a circle
      if (std::isinf(r))
        EXPECT_TRUE(std::isinf(scan.ranges[i])) << trial << " " << i;
      else
        EXPECT_NEAR(scan.ranges[i], r, 1e-4) << trial << " " << i;
    }
  }
}

TEST(LaserModel, OtherRobotsAreObstacles) {
  // Two robots side by side in adjacent lanes: each one's lasers see the other's footprint.
  const auto map = polytunnel(4, 10);
  LaneLayout layout(map);
  SimConfig c = quietConfig();
  c.num_robots = 2;
  c.robot_start_nodes = {map.node(layout.lanes()[1].nodes[4]).name,
                         map.node(layout.lanes()[2].nodes[4]).name};
  c.robot_motion.patrol = PatrolPolicy::kStay;
  c.clutter.bed_posts = false;
  c.laser.range_noise_std = 0.0;
  c.pickers = {{"p", true, "", "", 0}};
  FarmSimulator sim(map, c);
  const auto out = sim.step(0.1);
  int hits_on_other = 0;
  const double hl = 0.75, hw = 0.7;
  for (const auto& scan : out.scans) {
    const Pose2D other = sim.robotPose(1 - scan.robot_index);
    for (std::size_t b = 0; b < scan.ranges.size(); ++b) {
      if (!std::isfinite(scan.ranges[b])) continue;
      const double a = scan.sensor_pose.yaw + scan.angle_min + b * scan.angle_increment;
      const Eigen::Vector2d hit =
          scan.sensor_pose.position() + scan.ranges[b] * Eigen::Vector2d(std::cos(a), std::sin(a));
      const Eigen::Vector2d local = other.inverseTransform(hit);
      if (std::abs(std::abs(local.x()) - hl) < 1e-3 || std::abs(std::abs(local.y()) - hw) < 1e-3)
        ++hits_on_other;
    }
  }
  EXPECT_GT(hits_on_other, 20);
}

TEST(LaserModel, RangeNoiseStd) {
  LaserScene scene;
  scene.segments.push_back({{3.0, -10.0}, {3.0, 10.0}});
  LaserParams params;
  params.angle_min = -0.01;
  params.angle_max = 0.01;
  params.angle_increment = 0.01;
  std::mt19937_64 rng(3);
  std::vector<double> err;
  for (int k = 0; k < 3000; ++k) {
    const auto scan = castLaser(scene, {0.0, 0.0, 0.0}, params, k, rng);
    err.push_back(scan.ranges[1] - 3.0);
  }
  EXPECT_NEAR(mean(err), 0.0, 0.001);
  EXPECT_NEAR(stddev(err), params.range_noise_std, 0.0008);
}

TEST(LaserModel, SimulatorScanSeesPickerLegs) {
  // A robot standing in a lane sees a picker walking that lane: some beam returns within 2 cm of a leg.
  const auto map = polytunnel(4, 10);
  SimConfig c = quietConfig();
  c.pickers = {{"p", true, "t", "u", 0}};
  c.robot_start_nodes = {map.node(LaneLayout(map).lanes()[0].nodes[5]).name};
  c.robot_motion.patrol = PatrolPolicy::kStay;
  c.laser.range_noise_std = 0.0;
  c.clutter.bed_posts = false;
  FarmSimulator sim(map, c);
  int seen = 0;
  for (int k = 0; k < 100; ++k) {
    const auto out = sim.step(0.1);
    for (const auto& scan : out.scans) {
      const auto legs = sim.picker(0).legCentres();
      for (std::size_t b = 0; b < scan.ranges.size(); ++b) {
        if (!std::isfinite(scan.ranges[b])) continue;
        const double a = scan.sensor_pose.yaw + scan.angle_min + b * scan.angle_increment;
        const Eigen::Vector2d hit =
            scan.sensor_pose.position() + scan.ranges[b] * Eigen::Vector2d(std::cos(a), std::sin(a));
        const double d = std::min((hit - legs[0]).norm(), (hit - legs[1]).norm());
        // Every return lies on a leg circle (the only obstacles here), and some are seen.
        EXPECT_NEAR(d, 0.06, 0.02);
        ++seen;
      }
    }
  }
  EXPECT_GT(seen, 0);
}

// ---------------------------------------------------------------------------------------------------------
TEST(RfidModel, ReadProbabilityFallsWithDistance) {
  RfidParams p;
  std::mt19937_64 rng(5);
  double prev_rate = 1.0, prev_rssi = 0.0;
  for (double d : {0.5, 2.0, 4.0, 6.0, 7.5}) {
    int reads = 0;
    std::vector<double> rssi;
    const int n = 20000;
    for (int k = 0; k < n; ++k) {
      RfidReadingWithTruth r;
      if (simulateRfidRead(p, d, rng, r)) {
        ++reads;
        rssi.push_back(r.rssi);
        EXPECT_GE(r.phase, 0.0);
        EXPECT_LT(r.phase, 2 * M_PI);
      }
    }
    const double rate = static_cast<double>(reads) / n;
    EXPECT_NEAR(rate, p.p_max / (1.0 + std::exp((d - p.d50) / p.width)), 0.01) << d;
    EXPECT_LT(rate, prev_rate) << d;
    prev_rate = rate;
    if (rssi.size() > 100) {
      EXPECT_NEAR(mean(rssi), p.rssi_1m - 20.0 * std::log10(d), 0.3) << d;
      if (prev_rssi != 0.0) EXPECT_LT(mean(rssi), prev_rssi);
      prev_rssi = mean(rssi);
    }
  }
  RfidReadingWithTruth r;
  for (int k = 0; k < 1000; ++k) EXPECT_FALSE(simulateRfidRead(p, p.max_range + 0.1, rng, r));
}

TEST(UwbModel, RangeNoiseAndNlosOutliers) {
  UwbParams p;
  std::mt19937_64 rng(8);
  std::vector<double> los_err, nlos_err;
  int dropped = 0;
  const int n = 40000;
  for (int k = 0; k < n; ++k) {
    UwbRangeWithTruth u;
    if (!simulateUwbRange(p, 6.0, rng, u)) {
      ++dropped;
      continue;
    }
    EXPECT_DOUBLE_EQ(u.variance, p.range_std * p.range_std);
    (u.nlos ? nlos_err : los_err).push_back(u.range - 6.0);
  }
  EXPECT_NEAR(static_cast<double>(dropped) / n, p.p_dropout, 0.005);
  EXPECT_NEAR(mean(los_err), 0.0, 0.003);
  EXPECT_NEAR(stddev(los_err), p.range_std, 0.003);
  EXPECT_NEAR(static_cast<double>(nlos_err.size()) / (n - dropped), p.p_nlos, 0.005);
  EXPECT_NEAR(mean(nlos_err), p.nlos_mean, 0.08);
  for (double e : nlos_err) EXPECT_GT(e, -0.5);
  UwbRangeWithTruth u;
  for (int k = 0; k < 200; ++k) EXPECT_FALSE(simulateUwbRange(p, p.max_range + 1.0, rng, u));
}

TEST(CameraModel, BoxesOnlyInsideTheFieldOfView) {
  CameraParams p;
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-20.0, 20.0);
  const Pose2D cam{1.0, 2.0, 0.7};
  int inside = 0, detected = 0;
  for (int k = 0; k < 20000; ++k) {
    const Eigen::Vector2d pos(u(rng), u(rng));
    const Eigen::Vector2d q = cam.inverseTransform(pos);
    const bool in_fov =
        q.x() > 0.3 && std::abs(std::atan2(q.y(), q.x())) <= p.hfov / 2 && q.norm() <= p.max_range;
    const auto boxes = simulateCamera(p, cam, 1.2, {pos}, rng);
    if (!in_fov) {
      EXPECT_TRUE(boxes.empty()) << pos.transpose();
      continue;
    }
    ++inside;
    if (boxes.empty()) continue;
    ++detected;
    const auto& b = boxes.front();
    EXPECT_GE(b.x_offset, 0);
    EXPECT_LE(b.x_offset + b.width, p.image_width);
    EXPECT_GE(b.y_offset, 0);
    EXPECT_LE(b.y_offset + b.height, p.image_height);
    // Bearing of the noisy box centre: a few pixels' worth from the truth (unless clipped at the border).
    if (std::abs(b.true_bearing) < p.hfov / 2 - 0.1 && b.true_distance > 2.0)
      EXPECT_NEAR(b.bearing, b.true_bearing, 0.02);
  }
  ASSERT_GT(inside, 1000);
  // Misses: p_miss, plus boxes clipped to nothing at the image border (rare).
  EXPECT_NEAR(1.0 - static_cast<double>(detected) / inside, p.p_miss, 0.02);
}

// ---------------------------------------------------------------------------------------------------------
TEST(Robot, DrivesToGoalsAndRetargets) {
  const auto map = polytunnel(4, 6);
  LaneLayout layout(map);
  RobotMotionParams params;
  params.speed = 1.0;
  params.patrol = PatrolPolicy::kStay;
  const NodeIndex start = layout.lanes()[0].entry_end(), goal = layout.lanes()[3].far_end();
  SimulatedRobot robot(map, layout, "r", start, params, 1);
  robot.step(5.0);
  EXPECT_EQ(robot.pose().position(), map.position2d(start));  // stays without a goal
  robot.setGoal(goal);
  const double length = map.pathLength(start, goal);
  robot.step(length - 0.5);
  EXPECT_FALSE(robot.atGoal());
  robot.step(1.0);
  EXPECT_TRUE(robot.atGoal());
  EXPECT_NEAR((robot.pose().position() - map.position2d(goal)).norm(), 0.0, 1e-9);
  EXPECT_EQ(robot.goalsReached(), 1u);
  // Retarget in the middle of an edge: back to the start, turning on the edge.
  robot.setGoal(start);
  robot.step(1.0);
  robot.setGoal(goal);  // 1 m from the goal, turn back
  robot.step(1.0 + 1e-6);
  EXPECT_TRUE(robot.atGoal());
  // Lanes patrol visits lane ends forever.
  params.patrol = PatrolPolicy::kLanes;
  SimulatedRobot patrol(map, layout, "p", start, params, 2);
  std::set<NodeIndex> visited;
  for (int k = 0; k < 3000; ++k) {
    patrol.step(0.1);
    const NodeIndex n = patrol.nearestNode();
    if ((map.position2d(n) - patrol.pose().position()).norm() < 0.06) visited.insert(n);
  }
  for (const auto& lane : layout.lanes()) {
    EXPECT_TRUE(visited.count(lane.entry_end()));
    EXPECT_TRUE(visited.count(lane.far_end()));
  }
}

// ---------------------------------------------------------------------------------------------------------
TEST(FarmSimulator, DeterministicWithTheSameSeed) {
  const auto map = topology::loadMap(kTmap2);
  SimConfig c = quietConfig(123);
  c.num_robots = 2;
  FarmSimulator a(map, c), b(map, c);
  c.seed = 124;
  FarmSimulator other(map, c);
  SimOutputs oa, ob, oo;
  for (int k = 0; k < 60; ++k) {
    oa.append(a.step(1.0));
    ob.append(b.step(1.0));
    oo.append(other.step(1.0));
  }
  ASSERT_EQ(oa.gnss.size(), ob.gnss.size());
  ASSERT_FALSE(oa.gnss.empty());
  for (std::size_t k = 0; k < oa.gnss.size(); ++k) {
    if (oa.gnss[k].status != 0) continue;
    EXPECT_EQ(oa.gnss[k].latitude, ob.gnss[k].latitude);
    EXPECT_EQ(oa.gnss[k].longitude, ob.gnss[k].longitude);
  }
  ASSERT_EQ(oa.scans.size(), ob.scans.size());
  for (std::size_t k = 0; k < oa.scans.size(); ++k) EXPECT_EQ(oa.scans[k].ranges, ob.scans[k].ranges);
  ASSERT_EQ(oa.rfid.size(), ob.rfid.size());
  ASSERT_EQ(oa.uwb.size(), ob.uwb.size());
  for (std::size_t k = 0; k < oa.uwb.size(); ++k) EXPECT_EQ(oa.uwb[k].range, ob.uwb[k].range);
  ASSERT_EQ(oa.camera.size(), ob.camera.size());
  for (std::size_t i = 0; i < a.numPickers(); ++i) {
    EXPECT_EQ(a.pickerPose(i).x, b.pickerPose(i).x);
    EXPECT_EQ(a.pickerPose(i).y, b.pickerPose(i).y);
  }
  // A different seed gives different numbers.
  bool differs = false;
  for (std::size_t k = 0; k < std::min(oa.gnss.size(), oo.gnss.size()); ++k)
    if (oa.gnss[k].status == 0 && oo.gnss[k].status == 0 && oa.gnss[k].latitude != oo.gnss[k].latitude)
      differs = true;
  EXPECT_TRUE(differs);
}

TEST(FarmSimulator, PickersAndGnssIndependentOfRobotsAndSensorSwitches) {
  const auto map = topology::loadMap(kTmap2);
  SimConfig c = quietConfig(5);
  FarmSimulator a(map, c);
  c.enable.camera = false;
  c.enable.laser = false;
  c.num_robots = 3;
  c.robot_motion.patrol = PatrolPolicy::kRandom;
  FarmSimulator b(map, c);
  std::vector<GnssFixWithTruth> fa, fb;
  for (int k = 0; k < 120; ++k) {
    auto oa = a.step(0.5), ob = b.step(0.5);
    fa.insert(fa.end(), oa.gnss.begin(), oa.gnss.end());
    fb.insert(fb.end(), ob.gnss.begin(), ob.gnss.end());
    for (std::size_t i = 0; i < a.numPickers(); ++i) EXPECT_EQ(a.pickerPose(i).x, b.pickerPose(i).x);
  }
  ASSERT_EQ(fa.size(), fb.size());
  for (std::size_t k = 0; k < fa.size(); ++k) EXPECT_EQ(fa[k].error, fb[k].error);
}

TEST(FarmSimulator, CallersStandStillUntilReleasedThenFillTheNextTrays) {
  const auto map = topology::loadMap(kTmap2);
  SimConfig c = quietConfig(5);
  c.enable.camera = c.enable.laser = c.enable.uwb = false;
  c.calls.enabled = true;
  c.calls.tray_time_mean = 60.0;  // trays full after 30-90 s
  c.calls.reported_row_share = 1.0;
  c.calls.wrong_row_probability = 0.0;
  FarmSimulator sim(map, c);
  SimConfig off = quietConfig(5);
  off.enable = c.enable;
  FarmSimulator walking(map, off);  // calls off: the same walks as ever
  std::vector<PickerCall> calls;
  while (calls.empty() && sim.time() < 200.0) {
    const auto out = sim.step(0.5);
    walking.step(0.5);
    calls = out.calls;
    for (std::size_t i = 0; i < sim.numPickers() && calls.empty(); ++i)
      EXPECT_EQ(sim.pickerPose(i).x, walking.pickerPose(i).x);  // before any call: the same walk
  }
  ASSERT_EQ(calls.size(), 1u);
  EXPECT_GE(calls[0].stamp, 30.0);
  EXPECT_LE(calls[0].stamp, 90.0);
  const std::size_t i = calls[0].picker_index;
  EXPECT_EQ(calls[0].picker_id, sim.pickerSpec(i).id);
  EXPECT_EQ(calls[0].reported_row, map.laneNameOf(sim.pickerNearestNode(i)));  // every call reports its row
  EXPECT_TRUE(sim.pickerWaiting(i));
  const Pose2D at = sim.pickerPose(i);
  for (int k = 0; k < 60; ++k) {
    for (const auto& again : sim.step(0.5).calls) EXPECT_NE(again.picker_index, i);  // one call at a time
  }
  EXPECT_EQ(sim.pickerPose(i).x, at.x);  // waited 30 s where it called
  EXPECT_EQ(sim.pickerPose(i).y, at.y);
  sim.releasePicker(i);
  EXPECT_FALSE(sim.pickerWaiting(i));
  sim.step(5.0);
  EXPECT_GT((sim.pickerPose(i).position() - at.position()).norm(), 0.5);  // walks on
}

TEST(FarmSimulator, SensorRatesAndStamps) {
  const auto map = polytunnel(6, 8);
  SimConfig c = quietConfig(3);
  c.gnss.blackout_mean_interval = 0.0;
  FarmSimulator sim(map, c);
  const auto out = sim.advanceTo(10.0);
  EXPECT_DOUBLE_EQ(sim.time(), 10.0);
  EXPECT_EQ(out.gnss.size(), 10u * 3u);    // 1 Hz x 3 pickers
  EXPECT_EQ(out.scans.size(), 100u * 2u);  // 10 Hz x 2 lasers x 1 robot
  EXPECT_EQ(out.camera.size(), 50u * 2u);  // 5 Hz x 2 cameras
  for (std::size_t k = 0; k < out.gnss.size(); ++k)
    EXPECT_NEAR(out.gnss[k].stamp, 1.0 + static_cast<double>(k / 3), 1e-9);
  EXPECT_THROW(sim.advanceTo(5.0), std::invalid_argument);
  EXPECT_TRUE(sim.step(0.0).gnss.empty());
  // Small uneven steps give the same sensor grid.
  FarmSimulator s2(map, c);
  SimOutputs o2;
  while (s2.time() < 10.0 - 1e-9) o2.append(s2.step(std::min(0.037, 10.0 - s2.time())));
  EXPECT_EQ(o2.gnss.size(), out.gnss.size());
  EXPECT_EQ(o2.scans.size(), out.scans.size());
}

class FarmSimulatorOnMaps : public ::testing::TestWithParam<std::string> {};

TEST_P(FarmSimulatorOnMaps, RunsAndKeepsPickersOnTheGraph) {
  topology::TopologicalMap map;
  if (GetParam() == "polytunnel")
    map = polytunnel(10, 12);
  else if (GetParam() == "grid")
    map = gridMap();
  else
    map = topology::loadMap(GetParam());
  SimConfig c = quietConfig(17);
  c.num_robots = 2;
  FarmSimulator sim(map, c);
  std::size_t gnss = 0, scans = 0, rfid = 0, uwb = 0;
  for (int k = 0; k < 300; ++k) {
    const auto out = sim.step(1.0);
    gnss += out.gnss.size();
    scans += out.scans.size();
    rfid += out.rfid.size();
    uwb += out.uwb.size();
    for (std::size_t i = 0; i < sim.numPickers(); ++i) expectOnTour(map, sim.picker(i));
  }
  EXPECT_EQ(gnss, 900u);  // NO_FIX messages during blackouts included
  EXPECT_EQ(scans, 300u * 10u * 2u * 2u);
  EXPECT_GT(uwb, 0u);
  if (map.numLanes() > 0) {
    // Pickers start at a lane's entry end, in lanes.
    SimConfig c2 = quietConfig(17);
    FarmSimulator fresh(map, c2);
    for (std::size_t i = 0; i < fresh.numPickers(); ++i) {
      EXPECT_NE(fresh.pickerLane(i), topology::kNoLane);
      const auto& lane =
          fresh.laneLayout()
              .lanes()[static_cast<std::size_t>(fresh.laneLayout().orderOf(fresh.pickerLane(i)))];
      EXPECT_EQ(fresh.picker(i).state().from, lane.entry_end());
    }
    EXPECT_FALSE(sim.posts().empty());
  }
}

INSTANTIATE_TEST_SUITE_P(Maps, FarmSimulatorOnMaps,
                         ::testing::Values(kTmap2, kLegacy, std::string("polytunnel"), std::string("grid")));

// ---------------------------------------------------------------------------------------------------------
TEST(SimConfig, ShippedYamlLoadsAndUnknownKeysFail) {
  const SimConfig c = loadSimConfig(std::string(PL_PACKAGE_DIR) + "/config/sim.yaml");
  const SimConfig d;
  // The shipped file documents the defaults (Table I values).
  EXPECT_DOUBLE_EQ(c.picker_motion.p_reverse, 0.1);
  EXPECT_DOUBLE_EQ(c.picker_motion.t_reverse, 60.0);
  EXPECT_DOUBLE_EQ(c.gnss.offset_max, 3.5);
  EXPECT_DOUBLE_EQ(c.gnss.drift_std, 2.5);
  EXPECT_DOUBLE_EQ(c.gnss.white_std, 0.1);
  EXPECT_DOUBLE_EQ(c.gnss.blackout_min, 30.0);
  EXPECT_DOUBLE_EQ(c.gnss.blackout_max, 60.0);
  EXPECT_DOUBLE_EQ(c.laser.range_noise_std, d.laser.range_noise_std);
  EXPECT_DOUBLE_EQ(c.uwb.range_std, d.uwb.range_std);
  SimConfig e;
  EXPECT_THROW(applySimConfigYaml(YAML::Load("gnss: {drift_sd: 2}"), e, "x.yaml"), std::runtime_error);
  EXPECT_THROW(applySimConfigYaml(YAML::Load("gnss: {drift_std: abc}"), e, "x.yaml"), std::runtime_error);
  EXPECT_THROW(applySimConfigYaml(YAML::Load("robot_motion: {patrol: fly}"), e, "x.yaml"),
               std::runtime_error);
  applySimConfigYaml(YAML::Load("seed: 9\nenable: {camera: false}\nrobots: 2"), e, "x.yaml");
  EXPECT_EQ(e.seed, 9u);
  EXPECT_FALSE(e.enable.camera);
  EXPECT_EQ(e.num_robots, 2u);
}

TEST(FarmSimulator, RejectsBadConfiguration) {
  const auto map = polytunnel(4, 6);
  SimConfig c;
  c.time_step = 0.0;
  EXPECT_THROW(FarmSimulator(map, c), std::invalid_argument);
  c = SimConfig();
  c.laser.rate = -1.0;
  EXPECT_THROW(FarmSimulator(map, c), std::invalid_argument);
  c = SimConfig();
  c.robot_start_nodes = {"nope"};
  EXPECT_THROW(FarmSimulator(map, c), std::invalid_argument);
  FarmSimulator ok(map, SimConfig());
  EXPECT_THROW(ok.step(std::nan("")), std::invalid_argument);
  EXPECT_THROW(ok.setRobotGoal(0, 100000), std::out_of_range);
}
