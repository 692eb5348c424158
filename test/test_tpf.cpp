// Topological Particle Filter beyond the paper's equations (those: test_tpf_paper.cpp): bad input, the
// options file, determinism, what-if, statistical tracking on a synthetic lane and on the Riseholme map, the
// product's departures from the paper (lane changes, the GNSS bias per particle, the lane decision) and map
// edits.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <map>
#include <memory>
#include <set>
#include <tuple>

#include "picker_localisation/topology/map_io.h"
#include "picker_localisation/topology/synthetic_map.h"
#include "picker_localisation/tpf/topological_particle_filter.h"
#include "tpf_test_util.h"

using namespace picker_localisation;
using topology::NodeIndex;
using tpf::Particle;
using tpf::TopologicalParticleFilter;
using tpf::TpfParams;
using tpf::UpdateStatus;
using namespace tpf_test;  // laneMap, polytunnel, obsAt, paperTpf, staticParams, nodeFractions

// ------------------------------------------------------------------------------------------ bad input ------
TEST(TpfBadInput, RejectedObservationsLeaveTheBeliefUntouched) {
  auto map = polytunnel();
  TopologicalParticleFilter f(map, paperTpf(), 1);
  // Before initialisation: nothing to predict.
  EXPECT_FALSE(f.predictTo(5.0));
  ASSERT_TRUE(f.update(obsAt(10.0, {10}, {1.0})).ok());
  const auto before = f.particles();
  const auto belief_before = f.belief();
  auto same = [&]() {
    ASSERT_EQ(f.particles().size(), before.size());
    for (std::size_t i = 0; i < before.size(); ++i) {
      ASSERT_EQ(f.particles()[i].node, before[i].node);
      ASSERT_EQ(f.particles()[i].vx, before[i].vx);
      ASSERT_EQ(f.particles()[i].dwell, before[i].dwell);
      ASSERT_EQ(f.particles()[i].bias_variance, before[i].bias_variance);
    }
    EXPECT_EQ(f.belief().stamp, belief_before.stamp);
    EXPECT_EQ(f.belief().masses, belief_before.masses);
  };
  const double nan = std::nan("");
  struct Case {
    core::Observation o;
    UpdateStatus status;
  };
  std::vector<Case> cases = {
      {obsAt(11.0, {10}, {nan}), UpdateStatus::kRejectedInvalid},
      {obsAt(11.0, {10}, {-1.0}), UpdateStatus::kRejectedInvalid},
      {obsAt(11.0, {static_cast<NodeIndex>(map->numNodes())}, {1.0}), UpdateStatus::kRejectedInvalid},
      {obsAt(11.0, {topology::kInvalidNode}, {1.0}), UpdateStatus::kRejectedInvalid},
      {obsAt(11.0, {10, 11}, {1.0}), UpdateStatus::kRejectedInvalid},
      {obsAt(11.0, {}, {}), UpdateStatus::kRejectedInvalid},
      {obsAt(11.0, {10}, {0.0}), UpdateStatus::kRejectedInvalid},
      {obsAt(11.0, {10, 10}, {1.0, 1.0}), UpdateStatus::kRejectedInvalid},
      {obsAt(nan, {10}, {1.0}), UpdateStatus::kRejectedInvalid},
      {obsAt(8.5, {10}, {1.0}), UpdateStatus::kDroppedTooOld},  // 1.5 s late > 1 s window
  };
  core::Observation bad_velocity = obsAt(11.0, {10}, {1.0});
  bad_velocity.velocity = Eigen::Vector2d(nan, 0.0);
  cases.push_back({bad_velocity, UpdateStatus::kRejectedInvalid});
  // GNSS bias fields (gnss_bias_state): checked before a particle's bias is touched.
  auto with_bias = [&](const Eigen::Vector2d& removed, const Eigen::Matrix2d& cov, double rate,
                       bool position) {
    core::Observation o = obsAt(11.0, {10}, {1.0});
    if (position) o.position = map->position2d(10);
    o.bias_removed = removed;
    o.bias_covariance = cov;
    o.bias_drift_rate = rate;
    return o;
  };
  const Eigen::Matrix2d one = Eigen::Matrix2d::Identity();
  Eigen::Matrix2d not_psd;
  not_psd << 1.0, 2.0, 2.0, 1.0;
  for (const core::Observation& o :
       {with_bias({nan, 0.0}, one, 0.0, true), with_bias({0.0, 0.0}, nan * one, 0.0, true),
        with_bias({0.0, 0.0}, -one, 0.0, true), with_bias({0.0, 0.0}, not_psd, 0.0, true),
        with_bias({0.0, 0.0}, one, -1.0, true), with_bias({0.0, 0.0}, one, nan, true),
        with_bias({0.0, 0.0}, one, 0.0, false)})
    cases.push_back({o, UpdateStatus::kRejectedInvalid});
  core::Observation bad_position = obsAt(11.0, {10}, {1.0});
  bad_position.position = Eigen::Vector2d(0.0, nan);
  cases.push_back({bad_position, UpdateStatus::kRejectedInvalid});
  for (const auto& c : cases) {
    auto r = f.update(c.o);
    EXPECT_EQ(r.status, c.status) << r.reason;
    EXPECT_FALSE(r.ok());
    EXPECT_FALSE(r.reason.empty());
    same();
  }
  EXPECT_EQ(f.counters().rejected_invalid, cases.size() - 1);
  EXPECT_EQ(f.counters().dropped_too_old, 1u);
  // Predicting backwards does nothing.
  EXPECT_FALSE(f.predictTo(9.0));
  EXPECT_FALSE(f.predictTo(nan));
  same();
  // A late observation within the window is fused at the current time without moving the clock back.
  auto r = f.update(obsAt(9.5, {10}, {1.0}));
  EXPECT_EQ(r.status, UpdateStatus::kReordered);
  EXPECT_TRUE(r.ok());
  EXPECT_EQ(f.belief().stamp, 10.0);
  EXPECT_EQ(f.counters().reordered, 1u);
  EXPECT_EQ(f.belief().observations, 2u);
}

TEST(TpfBadInput, KhanIgnoresNonGnssSensors) {
  auto map = polytunnel();
  TopologicalParticleFilter f(map, TpfParams::presetForMethod("khan_unconnected"), 1);
  auto r = f.update(obsAt(0.0, {10}, {1.0}, true, "rfid"));
  EXPECT_EQ(r.status, UpdateStatus::kIgnoredSensor);
  EXPECT_FALSE(f.initialised());
  EXPECT_TRUE(f.update(obsAt(0.0, {10}, {1.0}, true, "gnss")).ok());
  EXPECT_EQ(f.counters().ignored_sensor, 1u);
}

TEST(TpfBadInput, ResetForgetsTheBelief) {
  auto map = polytunnel();
  TopologicalParticleFilter f(map, paperTpf(), 1);
  ASSERT_TRUE(f.update(obsAt(10.0, {10}, {1.0})).ok());
  f.reset();
  EXPECT_FALSE(f.initialised());
  EXPECT_TRUE(f.particles().empty());
  // An earlier stamp is fine after a reset (e.g. a bag restarted).
  auto r = f.update(obsAt(1.0, {50}, {1.0}));
  EXPECT_EQ(r.status, UpdateStatus::kAccepted);
  EXPECT_TRUE(r.initialised);
  EXPECT_EQ(f.belief().map_node, 50u);
}

// ------------------------------------------------------------------------------------------- params ------
TEST(TpfParamsTest, ConfigFileHoldsTableI) {
  const TpfParams p = TpfParams::fromYamlFile(std::string(PL_PACKAGE_DIR) + "/config/tpf.yaml");
  EXPECT_EQ(p.entropy_threshold, 0.6);
  EXPECT_EQ(p.jsd_threshold, 0.975);
  EXPECT_EQ(p.velocity_init_mean, 0.0);
  EXPECT_EQ(p.velocity_init_variance, 5e-2);
  EXPECT_EQ(p.velocity_noise_mean, 0.0);
  EXPECT_EQ(p.velocity_noise_variance, 5e-4);
  EXPECT_EQ(p.dwell_init_min, 0.0);
  EXPECT_EQ(p.dwell_init_max, 1.0);
  EXPECT_EQ(p.dwell_noise_min, -0.1);
  EXPECT_EQ(p.dwell_noise_max, 0.1);
  EXPECT_EQ(p.gammaFor("lidar").node, 0.25);
  EXPECT_EQ(p.gammaFor("lidar").velocity, 0.0);
  EXPECT_EQ(p.gammaFor("rfid").node, 1.0);
  EXPECT_EQ(p.gammaFor("rfid").velocity, 0.0);
  EXPECT_EQ(p.gammaFor("gnss").node, 1.0);
  EXPECT_EQ(p.gammaFor("gnss").velocity, 1.0);
  EXPECT_EQ(p.prediction_rate, 0.25);
  EXPECT_EQ(p.motion_model, tpf::MotionModel::kVelocity);
  EXPECT_TRUE(p.jsd_monitor);
  EXPECT_EQ(p.reinit_sensors,
            (std::vector<std::string>{
                "gnss", "uwb", "pose"}));  // measured default (tpf.md); pose: map-frame positions, as GNSS
  EXPECT_EQ(p.gammaFor("pose").node, 1.0);
  EXPECT_EQ(p.gammaFor("people").node, 0.25);
  EXPECT_TRUE(p.entropy_gate);
  EXPECT_FALSE(p.directed_motion);
  EXPECT_TRUE(p.accepted_sensors.empty());
  // Same as the compiled defaults.
  const TpfParams d;
  EXPECT_EQ(p.num_particles, d.num_particles);
  EXPECT_EQ(p.unconnected_jump_probability, d.unconnected_jump_probability);
  EXPECT_EQ(p.reorder_window, d.reorder_window);
  EXPECT_EQ(p.velocity_follows_edge, d.velocity_follows_edge);
  EXPECT_EQ(p.velocity_weight_product, d.velocity_weight_product);
  EXPECT_EQ(p.reverse_rate, d.reverse_rate);
  EXPECT_EQ(p.stand_rate, d.stand_rate);
  EXPECT_EQ(p.walk_rate, d.walk_rate);
  EXPECT_EQ(p.lane_change_model, d.lane_change_model);
  EXPECT_EQ(p.lane_change_leak, d.lane_change_leak);
  EXPECT_EQ(p.lane_change_max_hops, d.lane_change_max_hops);
  EXPECT_EQ(p.lane_change_keep_side, d.lane_change_keep_side);
  EXPECT_EQ(p.jsd_monitor, d.jsd_monitor);
  EXPECT_EQ(p.reinit_fraction, d.reinit_fraction);
}

TEST(TpfParamsTest, PresetsAndErrors) {
  auto kc = TpfParams::presetForMethod("khan_connected");
  EXPECT_EQ(kc.motion_model, tpf::MotionModel::kFixedLambda);
  EXPECT_EQ(kc.fixed_lambda, 0.1);
  EXPECT_EQ(kc.accepted_sensors, std::vector<std::string>{"gnss"});
  EXPECT_EQ(kc.unconnected_jump_probability, 0.0);
  EXPECT_FALSE(kc.jsd_monitor);
  auto ku = TpfParams::presetForMethod("khan_unconnected");
  EXPECT_GT(ku.unconnected_jump_probability, 0.0);
  EXPECT_FALSE(ku.entropy_gate);
  auto nm = TpfParams::presetForMethod("no_monitor");
  EXPECT_FALSE(nm.jsd_monitor);
  EXPECT_FALSE(nm.entropy_gate);
  EXPECT_EQ(nm.motion_model, tpf::MotionModel::kVelocity);
  auto cs = TpfParams::presetForMethod("constant_speed");
  EXPECT_EQ(cs.motion_model, tpf::MotionModel::kFixedLambda);
  EXPECT_TRUE(cs.jsd_monitor);
  EXPECT_TRUE(cs.accepted_sensors.empty());
  EXPECT_THROW(TpfParams::presetForMethod("nope"), std::invalid_argument);
  // YAML: the method preset wins over the file's mode switches; other values stay.
  auto y =
      TpfParams::fromYaml(YAML::Load("{method: khan_connected, num_particles: 77, motion_model: velocity}"));
  EXPECT_EQ(y.num_particles, 77u);
  EXPECT_EQ(y.motion_model, tpf::MotionModel::kFixedLambda);
  auto g = TpfParams::fromYaml(YAML::Load("{sensor_gammas: {sonar: {node: 0.5, velocity: 0.1}}}"));
  EXPECT_EQ(g.gammaFor("sonar").node, 0.5);
  EXPECT_EQ(g.gammaFor("gnss").velocity, 1.0);
  EXPECT_THROW(TpfParams::fromYaml(YAML::Load("{num_particles: many}")), std::runtime_error);
  // Bounds a farm can afford: the largest allowed values pass, one more does not.
  EXPECT_NO_THROW(TpfParams::fromYaml(
      YAML::Load("{num_particles: 100000, prediction_rate: 10, lane_change_max_hops: 50}")));
  EXPECT_THROW(TpfParams::fromYaml(YAML::Load("{num_particles: 100001}")), std::runtime_error);
  EXPECT_THROW(TpfParams::fromYaml(YAML::Load("{prediction_rate: 10.5}")), std::runtime_error);
  EXPECT_THROW(TpfParams::fromYaml(YAML::Load("{lane_change_max_hops: 51}")), std::runtime_error);
  EXPECT_THROW(TpfParams::fromYaml(YAML::Load("{jsd_threshold: 2.0}")), std::runtime_error);
  EXPECT_THROW(TpfParams::fromYaml(YAML::Load("{walk_rate: 0}")), std::runtime_error);
  EXPECT_THROW(TpfParams::fromYaml(YAML::Load("{stand_rate: -0.1}")), std::runtime_error);
  EXPECT_THROW(TpfParams::fromYaml(YAML::Load("{resampling: stratified}")), std::runtime_error);
  EXPECT_THROW(TpfParams::fromYaml(YAML::Load("{method: nope}")), std::runtime_error);
  EXPECT_THROW(TpfParams::fromYamlFile("/nonexistent/tpf.yaml"), std::runtime_error);
  TpfParams zero;
  zero.num_particles = 0;
  EXPECT_THROW(TopologicalParticleFilter(polytunnel(), zero, 1), std::invalid_argument);
}

// ------------------------------------------------------------------------- determinism and what-if ------
namespace {
void runSequence(TopologicalParticleFilter& f) {
  const auto& map = f.map();
  for (int k = 0; k < 30; ++k) {
    const Eigen::Vector2d truth(4.5, -3.0 + 0.5 * k);
    core::Observation o;
    o.stamp = k;
    o.sensor = (k % 3 == 2) ? "lidar" : "gnss";
    o.identifying = o.sensor == "gnss";
    o.picker_id = o.identifying ? "picker_1" : "";
    if (o.identifying) o.velocity = Eigen::Vector2d(0.0, 0.5);
    core::setGaussianLikelihood(o, map, truth + Eigen::Vector2d(0.3, -0.2), Eigen::Matrix2d::Identity());
    f.update(o);
    if (k % 5 == 4) f.predictTo(k + 0.5);
  }
}
}  // namespace

TEST(TpfDeterminism, SameSeedSameBeliefsBitForBit) {
  auto map = polytunnel();
  for (auto scheme : {tpf::ResamplingScheme::kLowVariance, tpf::ResamplingScheme::kMultinomial}) {
    TpfParams p = paperTpf();
    p.resampling = scheme;
    TopologicalParticleFilter a(map, p, 42), b(map, p, 42), c(map, p, 43);
    runSequence(a);
    runSequence(b);
    runSequence(c);
    EXPECT_EQ(a.belief().nodes, b.belief().nodes);
    EXPECT_EQ(a.belief().masses, b.belief().masses);  // exact double equality
    EXPECT_EQ(a.belief().entropy, b.belief().entropy);
    EXPECT_EQ(a.belief().jsd, b.belief().jsd);
    for (std::size_t i = 0; i < a.particles().size(); ++i) {
      ASSERT_EQ(a.particles()[i].node, b.particles()[i].node);
      ASSERT_EQ(a.particles()[i].vx, b.particles()[i].vx);
      ASSERT_EQ(a.particles()[i].dwell, b.particles()[i].dwell);
    }
    EXPECT_NE(a.belief().masses, c.belief().masses);  // another seed, another run
    // A copy continues exactly like the original.
    TopologicalParticleFilter d = a;
    auto o = obsAt(40.0, {50, 51}, {1.0, 2.0});
    a.update(o);
    d.update(o);
    EXPECT_EQ(a.belief().masses, d.belief().masses);
  }
}

TEST(TpfWhatIf, LiveFilterUntouched) {
  auto map = polytunnel();
  TopologicalParticleFilter f(map, paperTpf(), 3);
  runSequence(f);
  const auto particles = f.particles();
  const auto belief = f.belief();
  const auto counters = f.counters();

  const auto ahead = f.predictAhead(8.0, 5);
  EXPECT_NEAR(ahead.stamp, belief.stamp + 8.0, 1e-12);
  EXPECT_TRUE(ahead.initialised);
  double total = 0.0;
  for (double m : ahead.masses) total += m;
  EXPECT_NEAR(total, 1.0, 1e-9);
  // Same seed, same answer; the live filter's generator state is not consumed.
  EXPECT_EQ(f.predictAhead(8.0, 5).masses, ahead.masses);
  EXPECT_EQ(f.predictAhead(8.0, 0).masses, f.predictAhead(8.0, 0).masses);

  tpf::UpdateResult r;
  const auto post = f.posteriorUnder(obsAt(0.0, {100}, {1.0}), 2.0, 9, &r);
  EXPECT_TRUE(r.ok());
  EXPECT_EQ(post.map_node, 100u);  // disjoint identifying observation re-initialises the copy
  EXPECT_NEAR(post.stamp, belief.stamp + 2.0, 1e-12);
  const auto bad = f.posteriorUnder(obsAt(0.0, {100}, {std::nan("")}), 2.0, 9, &r);
  EXPECT_EQ(r.status, UpdateStatus::kRejectedInvalid);
  EXPECT_NEAR(bad.stamp, belief.stamp + 2.0, 1e-12);

  ASSERT_EQ(f.particles().size(), particles.size());
  for (std::size_t i = 0; i < particles.size(); ++i) {
    ASSERT_EQ(f.particles()[i].node, particles[i].node);
    ASSERT_EQ(f.particles()[i].vx, particles[i].vx);
    ASSERT_EQ(f.particles()[i].dwell, particles[i].dwell);
  }
  EXPECT_EQ(f.belief().masses, belief.masses);
  EXPECT_EQ(f.belief().stamp, belief.stamp);
  EXPECT_EQ(f.counters().accepted, counters.accepted);
  // The live filter continues as if nothing happened: same as a twin that never answered a what-if.
  TopologicalParticleFilter twin(map, paperTpf(), 3);
  runSequence(twin);
  auto o = obsAt(40.0, {50}, {1.0});
  f.update(o);
  twin.update(o);
  EXPECT_EQ(f.belief().masses, twin.belief().masses);
}

// ------------------------------------------------------------------------------------------ tracking ------
namespace {
// A picker walking the node sequence `path` at `speed` m/s (straight segments between the nodes), observed
// by exact GNSS at 1 Hz (sigma 0.5 m likelihood, exact velocity). Returns the largest hop error after
// `converge_s` seconds and the share of steps within one hop.
struct TrackStats {
  int max_hops = 0;
  double worst_time = 0.0;  // s, when max_hops happened
  double within_one = 0.0;
};
TrackStats trackWalk(TopologicalParticleFilter& f, const std::vector<NodeIndex>& path, double speed,
                     double converge_s) {
  const auto& map = f.map();
  std::vector<Eigen::Vector2d> pts;
  for (NodeIndex n : path) pts.push_back(map.position2d(n));
  TrackStats s;
  int steps = 0, good = 0;
  std::size_t seg = 0;
  double along = 0.0;
  for (double t = 0.0; seg + 1 < pts.size(); t += 1.0) {
    const Eigen::Vector2d d = pts[seg + 1] - pts[seg];
    const Eigen::Vector2d pos = pts[seg] + d * (along / d.norm());
    const Eigen::Vector2d vel = d.normalized() * speed;
    core::Observation o;
    o.stamp = t;
    o.sensor = "gnss";
    o.identifying = true;
    o.picker_id = "picker_1";
    o.velocity = vel;
    core::GaussianLikelihoodOptions opt;
    opt.cutoff_sigmas = 4.0;
    core::setGaussianLikelihood(o, map, pos, 0.25 * Eigen::Matrix2d::Identity(), opt);
    EXPECT_TRUE(f.update(o).ok());
    if (t >= converge_s) {
      const int hops = map.hopDistance(f.belief().map_node, map.nearestNode(pos));
      EXPECT_GE(hops, 0);
      if (hops > s.max_hops) {
        s.max_hops = hops;
        s.worst_time = t;
      }
      ++steps;
      good += hops <= 1 ? 1 : 0;
    }
    along += speed;
    while (seg + 1 < pts.size() && along >= (pts[seg + 1] - pts[seg]).norm()) {
      along -= (pts[seg + 1] - pts[seg]).norm();
      ++seg;
    }
  }
  s.within_one = steps ? static_cast<double>(good) / steps : 0.0;
  return s;
}
}  // namespace

TEST(TpfTracking, SyntheticLaneWithExactGnssWithinOneHop) {
  auto map = polytunnel();  // 12 lanes x 10 nodes, 1.5 m apart, 3 m node spacing
  // Up lane 4 from the headland to the far headland: within one hop at every step after 5 s, for both
  // readings of Eq. 2 in time.
  std::vector<NodeIndex> up;
  up.push_back(*map->index("H4"));
  for (int j = 0; j < 10; ++j) up.push_back(*map->index("r4_" + std::to_string(j)));
  up.push_back(*map->index("T4"));
  for (std::uint64_t seed : {1u, 2u, 3u, 4u, 5u}) {
    TopologicalParticleFilter f(map, paperTpf(), seed);
    const TrackStats s = trackWalk(f, up, 0.5, 5.0);
    EXPECT_LE(s.max_hops, 1) << "seed " << seed << " at t = " << s.worst_time << " s";
    EXPECT_LE(map->hopDistance(f.belief().map_node, *map->index("T4")), 1);
  }
  // Up and back down (a reversal at the far end): the particles must turn (dead end); at most two hops
  // while they do, within one hop at >= 95 % of the steps.
  std::vector<NodeIndex> back = up;
  for (int j = 9; j >= 0; --j) back.push_back(*map->index("r4_" + std::to_string(j)));
  for (std::uint64_t seed : {1u, 2u, 3u, 4u, 5u}) {
    TopologicalParticleFilter f(map, paperTpf(), seed);
    const TrackStats s = trackWalk(f, back, 0.5, 5.0);
    EXPECT_LE(s.max_hops, 2) << "seed " << seed << " at t = " << s.worst_time << " s";
    EXPECT_GE(s.within_one, 0.95) << "seed " << seed;
    EXPECT_EQ(f.map().lane(f.belief().map_node), map->lane(*map->index("r4_0")));
  }
}

TEST(TpfTracking, RiseholmeLaneWithExactGnssWithinOneHop) {
  auto map = std::make_shared<const topology::TopologicalMap>(
      topology::loadMap(std::string(PL_PACKAGE_DIR) + "/config/maps/riseholme.tmap2"));
  ASSERT_GT(map->numLanes(), 0u);
  // The longest lane, walked end to end, in the order of the lane's chain.
  topology::LaneIndex best = 0;
  for (std::size_t l = 0; l < map->numLanes(); ++l)
    if (map->laneNodes(static_cast<topology::LaneIndex>(l)).size() > map->laneNodes(best).size())
      best = static_cast<topology::LaneIndex>(l);
  const auto& lane = map->laneNodes(best);
  // End node: a lane node with at most one lane neighbour; then the shortest path to the other end.
  NodeIndex a = lane.front(), b = lane.front();
  double far = -1.0;
  for (NodeIndex n : lane)
    if (map->distance(lane.front(), n) > far) far = map->distance(lane.front(), n), a = n;
  far = -1.0;
  for (NodeIndex n : lane)
    if (map->distance(a, n) > far) far = map->distance(a, n), b = n;
  const auto path = map->shortestPath(a, b);
  ASSERT_GE(path.size(), 5u);
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    TopologicalParticleFilter f(map, paperTpf(), seed);
    const TrackStats s = trackWalk(f, path, 0.5, 5.0);
    EXPECT_LE(s.max_hops, 1) << "seed " << seed;
  }
}

TEST(TpfTracking, SparseUpdatesOnALargeMap) {
  // 10,000 nodes: the filter tracks the same way; only the support is ever touched.
  auto map = std::make_shared<const topology::TopologicalMap>(
      topology::makePolytunnelMap(topology::polytunnelSpecWithNodes(10000)));
  std::vector<NodeIndex> path;
  for (int j = 0; j < 30; ++j) path.push_back(*map->index("r7_" + std::to_string(j)));
  TopologicalParticleFilter f(map, paperTpf(), 1);
  const TrackStats s = trackWalk(f, path, 0.5, 5.0);
  EXPECT_LE(s.max_hops, 1);
  EXPECT_LT(f.belief().nodes.size(), 50u);
}

// ------------------------------------------------------------------------- product departures from the paper
// ---
TEST(TpfLaneChange, ParticlesLeavingALaneEndWalkIntoTheAdjacentLane) {
  // All particles at the end node of lane 5 walking out of it (-y, towards the headland node H5). With the
  // lane-change model they follow H5 -> H4 -> r4_0 or H5 -> H6 -> r6_0 into a neighbouring lane; without it
  // they turn at random on the headland and walk along it (velocity follows the edge taken). 20 s: ~17 m.
  auto map = polytunnel();
  const NodeIndex start = *map->index("r5_0");
  auto shares = [&](bool lane_change) {
    TpfParams p;  // product defaults
    p.num_particles = 4000;
    p.lane_change_model = lane_change;
    p.reverse_rate = 0.0;
    p.velocity_init_mean = -0.6;  // v = (-0.6, -0.6): the first jump is to H5, then the heading is -y
    p.velocity_init_variance = 0.0;
    p.dwell_init_max = 0.0;
    p.unconnected_jump_probability = 0.0;
    TopologicalParticleFilter f(map, p, 11);
    EXPECT_TRUE(f.update(obsAt(0.0, {start}, {1.0})).ok());
    for (int k = 1; k <= 20; ++k) f.predictTo(k);  // ~17 m at 0.85 m/s: not yet at the lanes' far ends
    std::size_t left = 0, adjacent = 0;
    for (const auto& q : f.particles()) {
      const auto lane = map->lane(q.node);
      if (lane == map->lane(start)) continue;
      ++left;
      if (lane >= 0 && (map->laneName(lane) == "row_4" || map->laneName(lane) == "row_6")) ++adjacent;
    }
    return std::make_pair(static_cast<double>(left) / f.particles().size(),
                          left ? static_cast<double>(adjacent) / left : 0.0);
  };
  const auto with = shares(true), without = shares(false);
  EXPECT_GT(with.first, 0.3);   // many particles left the lane
  EXPECT_GT(with.second, 0.8);  // ... and most of them are in lane 4 or 6
  EXPECT_LT(without.second, with.second - 0.2);
}

// Side memory: particles leave lane 5 at its near end into lane 4 or 6 (no memory yet: either side), walk
// that lane to its far end and leave it again. With lane_change_keep_side 0.8 most carry on the same way (6
// -> 7, 4 -> 3); with 0.5 (no memory) they go back to lane 5 as often as on.
TEST(TpfLaneChange, ParticlesRememberTheSideOfTheirLastLaneChange) {
  auto map = polytunnel();
  const NodeIndex start = *map->index("r5_0");
  auto carry_on_share = [&](double keep, std::size_t* changed) {
    TpfParams p;  // product defaults
    p.num_particles = 4000;
    p.lane_change_keep_side = keep;
    p.reverse_rate = 0.0;
    p.velocity_init_mean = -0.6;  // first jump to H5, as in the test above
    p.velocity_init_variance = 0.0;
    p.dwell_init_max = 0.0;
    p.unconnected_jump_probability = 0.0;
    TopologicalParticleFilter f(map, p, 11);
    EXPECT_TRUE(f.update(obsAt(0.0, {start}, {1.0})).ok());
    for (int k = 1; k <= 40; ++k) f.predictTo(k);  // two lane changes: ~34 m at ~0.85 m/s
    std::size_t on = 0, back = 0;
    for (const auto& q : f.particles()) {
      const auto lane = map->lane(q.node);
      if (lane < 0 || q.last_lane_change == 0) continue;  // on a headland, or never completed a lane change
      const std::string name = map->laneName(lane);
      if (name == "row_3" || name == "row_7") ++on;
      if (name == "row_5") ++back;
    }
    *changed = on + back;
    return on + back ? static_cast<double>(on) / static_cast<double>(on + back) : 0.0;
  };
  std::size_t changed_keep = 0, changed_none = 0;
  const double keep = carry_on_share(0.8, &changed_keep), none = carry_on_share(0.5, &changed_none);
  EXPECT_GT(changed_keep, 1000u);  // most have made both lane changes in 40 s
  EXPECT_GT(changed_none, 1000u);
  EXPECT_GT(keep, 0.75) << keep;  // measured 0.81 (0.49 without memory)
  EXPECT_NEAR(none, 0.5, 0.1) << none;
}

TEST(TpfLaneChange, VelocityFollowsTheEdgeAndParticlesReverse) {
  auto map = laneMap();
  TpfParams p = staticParams(2000);
  p.velocity_follows_edge = true;
  p.velocity_init_mean = 0.5;
  p.dwell_init_max = 0.0;
  TopologicalParticleFilter f(map, p, 7);
  ASSERT_TRUE(f.update(obsAt(0.0, {2}, {1.0})).ok());
  ASSERT_TRUE(f.predictTo(3.0));
  for (const auto& q : f.particles())
    if (q.node == 3) {
      EXPECT_NEAR(q.vy, 0.0, 1e-6);  // heading = the edge taken (+x): the y component is gone
      EXPECT_NEAR(q.vx, std::hypot(0.5, 0.5) + 0.5 * (1.0 - std::hypot(0.5, 0.5)) / 10.0,
                  1e-4);  // Eq. 7 on the speed
    }
  // reverse_rate: about 1 - exp(-rate t) of the particles have turned round.
  TpfParams r = staticParams(20000);
  r.reverse_rate = 0.05;
  r.velocity_init_mean = 0.5;
  r.velocity_init_variance = 0.0;
  TopologicalParticleFilter g(map, r, 9);
  ASSERT_TRUE(g.update(obsAt(0.0, {2}, {1.0})).ok());
  ASSERT_TRUE(g.predictTo(2.0));
  std::size_t reversed = 0;
  for (const auto& q : g.particles()) reversed += q.vx < 0.0f ? 1 : 0;
  EXPECT_NEAR(static_cast<double>(reversed) / g.particles().size(), 1.0 - std::exp(-0.05 * 2.0), 0.01);
}

// ------------------------------------------------------------------------------ GNSS bias per particle
// ------
namespace {
// A GNSS observation as gnss_ingest builds it: the corrected fix, its node likelihood, the bias removed and
// its covariance (the prior before any sighting), the device's drift rate.
core::Observation biasedFix(const topology::TopologicalMap& map, double stamp,
                            const Eigen::Vector2d& corrected, double fix_variance,
                            const Eigen::Vector2d& bias_removed, double bias_variance, double drift_rate) {
  core::Observation o = obsAt(stamp, {}, {});
  o.position = corrected;
  o.position_covariance = fix_variance * Eigen::Matrix2d::Identity();
  core::setGaussianLikelihood(o, map, corrected, o.position_covariance);
  o.bias_removed = bias_removed;
  o.bias_covariance = bias_variance * Eigen::Matrix2d::Identity();
  o.bias_drift_rate = drift_rate;
  return o;
}
}  // namespace

TEST(TpfGnssBias, KalmanUpdatePerParticleAndPredictiveWeights) {
  // Lane map, nodes 3 m apart: R = gnss_bias_fix_std^2 + 3^2 / 12 = 1 + 0.75. Particles half at n1 (x = 3),
  // half at n2 (x = 6). Fix: corrected (3.5, 0) + removed bias (0.5, 0) = raw (4, 0); prior variance 2, no
  // drift. n1: y = 4 - 3 - 0.5 = 0.5 ... per axis: y1 = (0.5, 0), y2 = (-2.5, 0); S = 3.75, K = 2 / 3.75.
  // Weights N(y; 0, S I) (the node likelihood L is not used): w1 / w2 = exp(-0.5 (0.25 - 6.25) / 3.75) =
  // e^0.8.
  auto map = laneMap();
  TpfParams p = staticParams(2000);
  p.gnss_bias_state = true;
  p.gnss_bias_fix_std = 1.0;
  TopologicalParticleFilter f(map, p, 3);
  const NodeIndex n1 = *map->index("n1"), n2 = *map->index("n2");
  ASSERT_TRUE(f.update(obsAt(0.0, {n1, n2}, {1.0, 1.0}, true, "uwb")).ok());
  const double at_n1 = nodeFractions(f.particles())[n1];  // ~0.5, drawn
  core::Observation o = biasedFix(*map, 0.0, {3.5, 0.0}, 1.0, {0.5, 0.0}, 2.0, 0.0);
  o.nodes = {n1, n2};
  o.likelihood = {0.01, 1.0};  // favours n2: ignored by the bias state
  const auto r = f.update(o);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_FALSE(r.reinitialised);
  const double ratio = std::exp(0.8);
  EXPECT_NEAR(f.belief().massOf(n1), at_n1 * ratio / (at_n1 * ratio + 1.0 - at_n1), 1e-6);
  const double s = 3.75, k = 2.0 / s;
  for (const Particle& q : f.particles()) {
    const double y = q.node == n1 ? 0.5 : -2.5;
    EXPECT_NEAR(q.bias_x, 0.5 + k * y, 1e-5);
    EXPECT_NEAR(q.bias_y, 0.0, 1e-6);
    EXPECT_NEAR(q.bias_variance, 2.0 * 1.75 / s, 1e-5);
  }
  // The next fix 10 s later: the bias is the Gauss-Markov process of the device prior (mean m = 0.5, P = 2,
  // initial rate Q = 0.01, correlation time 2 P / Q = 400 s): before the update b -> m + a (b - m) and
  // var -> a^2 var + (1 - a^2) P with a = exp(-10 / 400).
  std::map<NodeIndex, float> bias_before;
  for (const Particle& q : f.particles()) bias_before[q.node] = q.bias_x;
  core::Observation later = biasedFix(*map, 10.0, {3.5, 0.0}, 1.0, {0.5, 0.0}, 2.0, 0.01);
  ASSERT_TRUE(f.update(later).ok());
  const double a = std::exp(-10.0 / 400.0);
  const double v0 = a * a * 2.0 * 1.75 / s + (1.0 - a * a) * 2.0, v1 = v0 * 1.75 / (v0 + 1.75);
  for (const Particle& q : f.particles()) {
    EXPECT_NEAR(q.bias_variance, v1, 1e-5);
    const double predicted = 0.5 + a * (bias_before[q.node] - 0.5);
    const double y = 4.0 - map->position2d(q.node).x() - predicted;
    EXPECT_NEAR(q.bias_x, predicted + v0 / (v0 + 1.75) * y, 1e-4);
  }
}

namespace {
// Share of the belief's mass in the lane of `node`.
double laneMass(const topology::TopologicalMap& map, const tpf::Belief& b, NodeIndex node) {
  double share = 0.0;
  for (std::size_t j = 0; j < b.nodes.size(); ++j)
    if (map.lane(b.nodes[j]) == map.lane(node)) share += b.masses[j];
  return share;
}
}  // namespace

TEST(TpfGnssBias, LaneSwapsKeepHypothesesTheFixesCannotTellApart) {
  // Every particle starts in lane 5 (one sighting); then 300 s of phone fixes halfway between lanes 5 and 6
  // with the phone's prior (3.2 m per axis): the fixes cannot tell the two lanes apart. Static particles
  // never leave lane 5 by themselves (no edge crosses a lane); with lane swaps, lane 6 gets about as much
  // mass as lane 5 (and lanes 4 and 7, 2.25 m from the fixes, less). With a tight prior (a robot measured the
  // bias) a swap would need a 1.5 m error the prior rules out: none.
  auto map = polytunnel();
  const NodeIndex here = *map->index("r5_5"), there = *map->index("r6_5");
  const Eigen::Vector2d between = 0.5 * (map->position2d(here) + map->position2d(there));
  auto shares = [&](double rate, double prior_variance) {
    TpfParams p = staticParams(1000);
    p.gnss_bias_state = true;
    p.lane_swap_rate = rate;
    p.lane_swap_memory = 30.0;  // the sighting pauses swaps this long
    p.lane_masses_by_swap_prior = false;  // the particles' own counts (tested below)
    TopologicalParticleFilter f(map, p, 5);
    EXPECT_TRUE(f.update(obsAt(0.0, {here}, {1.0}, true, "uwb")).ok());
    for (int k = 1; k <= 300; ++k)
      EXPECT_TRUE(
          f.update(biasedFix(*map, k, between, 9.0, {0.0, 0.0}, prior_variance, 2.0 * 6.25 / 300.0)).ok());
    return std::make_pair(laneMass(*map, f.belief(), here), laneMass(*map, f.belief(), there));
  };
  const auto off = shares(0.0, 10.25);
  EXPECT_GT(off.first, 0.999);
  const auto on = shares(0.1, 10.25);
  EXPECT_GT(on.second, 0.15);
  EXPECT_GT(on.first, 0.15);
  EXPECT_GT(on.first + on.second, 0.4);
  const auto tight = shares(0.1, 0.05);
  EXPECT_GT(tight.first, 0.999);
}

TEST(TpfDecision, LaneMassesFromTheDevicePriorNotFromParticleNoise) {
  // 300 s of phone fixes (3.2 m prior per axis) 0.3 m from lane 5 towards lane 6, lanes 1.5 m apart: every
  // lane explains them with its own bias; the device prior prefers the smallest, so lane 5 (bias 0.3 m), then
  // lane 6 (1.2 m), then lane 4 (1.8 m). Counting particles, the lanes' masses are whatever the swaps and
  // resampling left, different for every seed; Rao-Blackwellised over the lane (lane_masses_by_swap_prior),
  // every seed gives the prior's order and nearly the same masses.
  auto map = polytunnel();
  const NodeIndex lane5 = *map->index("r5_5"), lane4 = *map->index("r4_5"), lane6 = *map->index("r6_5");
  const Eigen::Vector2d across = map->position2d(lane6) - map->position2d(lane5);
  const Eigen::Vector2d fixes = map->position2d(lane5) + 0.2 * across;
  auto masses = [&](bool by_prior, std::uint64_t seed) {
    TpfParams p = staticParams(1000);
    p.gnss_bias_state = true;
    p.lane_masses_by_swap_prior = by_prior;
    p.lane_swap_memory = 30.0;  // the first sighting pauses swaps this long
    TopologicalParticleFilter f(map, p, seed);
    EXPECT_TRUE(f.update(obsAt(0.0, {lane5}, {1.0}, true, "uwb")).ok());
    for (int k = 1; k <= 300; ++k)
      EXPECT_TRUE(f.update(biasedFix(*map, k, fixes, 9.0, {0.0, 0.0}, 10.25, 2.0 * 6.25 / 300.0)).ok());
    return std::make_tuple(laneMass(*map, f.belief(), lane5), laneMass(*map, f.belief(), lane4),
                           laneMass(*map, f.belief(), lane6), map->lane(f.belief().map_node));
  };
  auto spread = [&](bool by_prior, int* lane5_decisions) {
    double lo = 1.0, hi = 0.0;
    *lane5_decisions = 0;
    for (std::uint64_t seed = 1; seed <= 8; ++seed) {
      const auto [m5, m4, m6, decided] = masses(by_prior, seed);
      if (by_prior) {
        EXPECT_GT(m5, m6) << "seed " << seed;
        EXPECT_GT(m6, m4) << "seed " << seed;
      }
      lo = std::min(lo, m5);
      hi = std::max(hi, m5);
      if (decided == map->lane(lane5)) ++*lane5_decisions;
    }
    return hi - lo;
  };
  int decided_counting = 0, decided_by_prior = 0;
  const double spread_counting = spread(false, &decided_counting);
  const double spread_by_prior = spread(true, &decided_by_prior);
  EXPECT_EQ(decided_by_prior, 8);
  EXPECT_LT(spread_by_prior, 0.005);  // measured 1e-5 (counting: 0.019, lane 5 named in 6 of 8 seeds)
  EXPECT_GT(spread_counting, 3.0 * spread_by_prior);
  EXPECT_LT(decided_counting, 8);
  EXPECT_TRUE(TpfParams().lane_masses_by_swap_prior);

  // A unit described as nearly unbiased (prior 1 cm): every other lane's share underflows to 0. The belief
  // still lists each node once, with a positive mass (a node listed twice made gnss_ingest drop the belief).
  TpfParams p = staticParams(1000);
  p.gnss_bias_state = true;
  p.lane_swap_memory = 30.0;
  TopologicalParticleFilter f(map, p, 3);
  ASSERT_TRUE(f.update(obsAt(0.0, {lane5}, {1.0}, true, "uwb")).ok());
  for (int k = 1; k <= 60; ++k)
    ASSERT_TRUE(f.update(biasedFix(*map, k, map->position2d(lane5), 9.0, {0.0, 0.0}, 1e-4, 1e-6)).ok());
  const std::set<NodeIndex> unique(f.belief().nodes.begin(), f.belief().nodes.end());
  EXPECT_EQ(unique.size(), f.belief().nodes.size());
  for (double m : f.belief().masses) EXPECT_GT(m, 0.0);
  EXPECT_GT(laneMass(*map, f.belief(), lane5), 0.999);
}

TEST(TpfDecision, MapNodeByLaneFirst) {
  // Observations split the static particles: lane 5 holds 0.6 of the mass over three nodes (0.2 each), lane 6
  // holds 0.4 on one node. Eq. 10 literally names lane 6's node (the single heaviest); by lane first, lane 5,
  // and within it the node the likelihood favours.
  auto map = polytunnel();
  const NodeIndex a = *map->index("r5_4"), b = *map->index("r5_5"), c = *map->index("r5_6"),
                  d = *map->index("r6_5");
  auto decide = [&](bool by_lane) {
    TpfParams p = staticParams(20000);
    p.map_node_by_lane = by_lane;
    TopologicalParticleFilter f(map, p, 11);
    EXPECT_TRUE(f.update(obsAt(0.0, {a, b, c, d}, {1.0, 1.0, 1.0, 1.0})).ok());  // a quarter at each
    EXPECT_TRUE(f.update(obsAt(0.0, {a, b, c, d}, {0.2, 0.21, 0.19, 0.4})).ok());
    EXPECT_NEAR(f.belief().massOf(d), 0.4, 0.02);
    return f.belief().map_node;
  };
  EXPECT_EQ(decide(false), d);
  EXPECT_EQ(decide(true), b);

  // Coarse to fine: a picker stopped just inside a lane, the lane unknown. Lanes 4, 5 and 6 hold 0.2 each at
  // their first node, the headland node H5 0.4: heavier than any one lane, lighter than the lanes together.
  // The picker is in a lane, so the decision is a lane's node (lane 5's by the likelihood's small
  // preference); comparing H5 with each lane had named the headland.
  const NodeIndex l4 = *map->index("r4_0"), l5 = *map->index("r5_0"), l6 = *map->index("r6_0"),
                  head = *map->index("H5");
  TpfParams p = staticParams(20000);
  p.map_node_by_lane = true;
  TopologicalParticleFilter f(map, p, 11);
  ASSERT_TRUE(f.update(obsAt(0.0, {l4, l5, l6, head}, {1.0, 1.0, 1.0, 1.0})).ok());
  ASSERT_TRUE(f.update(obsAt(0.0, {l4, l5, l6, head}, {0.19, 0.22, 0.19, 0.4})).ok());
  EXPECT_NEAR(f.belief().massOf(head), 0.4, 0.02);
  EXPECT_EQ(f.belief().map_node, l5);
  // With the headland holding more than the lanes together, the headland node is named.
  TopologicalParticleFilter g(map, p, 11);
  ASSERT_TRUE(g.update(obsAt(0.0, {l4, l5, l6, head}, {1.0, 1.0, 1.0, 1.0})).ok());
  ASSERT_TRUE(g.update(obsAt(0.0, {l4, l5, l6, head}, {0.1, 0.12, 0.1, 0.68})).ok());
  EXPECT_EQ(g.belief().map_node, head);
  // The shipped defaults decide by lane; the paper's and Khan's presets follow Eq. 10.
  EXPECT_TRUE(TpfParams().map_node_by_lane);
  EXPECT_FALSE(TpfParams::presetForMethod("paper_tpf").map_node_by_lane);
  EXPECT_FALSE(TpfParams::presetForMethod("khan_connected").map_node_by_lane);
}

TEST(TpfGnssBias, LaneSwapsPauseWhileARobotSeesThePicker) {
  // The same ambiguous fixes, but a UWB fix on lane 5 every 20 s (within lane_swap_memory): lane 5 keeps it.
  auto map = polytunnel();
  const NodeIndex here = *map->index("r5_5"), there = *map->index("r6_5");
  const Eigen::Vector2d between = 0.5 * (map->position2d(here) + map->position2d(there));
  TpfParams p = staticParams(1000);
  p.gnss_bias_state = true;
  p.lane_swap_memory = 30.0;
  TopologicalParticleFilter f(map, p, 5);
  for (int k = 0; k <= 300; ++k) {
    if (k % 20 == 0) ASSERT_TRUE(f.update(obsAt(k, {here}, {1.0}, true, "uwb")).ok());
    if (k > 0)
      ASSERT_TRUE(
          f.update(biasedFix(*map, k + 0.5, between, 9.0, {0.0, 0.0}, 10.25, 2.0 * 6.25 / 300.0)).ok());
  }
  EXPECT_GT(laneMass(*map, f.belief(), here), 0.999);
  EXPECT_LT(laneMass(*map, f.belief(), there), 1e-3);
}

TEST(TpfGnssBias, AReportedRowMovesTheBeliefIntoItWeighedAgainstTheFixes) {
  // A minute of phone fixes on lane 5 holds every particle there. The picker reports lane 6 (likelihood 1
  // there, 0.2 elsewhere). Weighting alone cannot move the belief (no particle in lane 6): it stays in
  // lane 5. With the lane-evidence moves (swap proposals accepted by the row's likelihood ratio and the
  // device prior), most of the mass goes to lane 6, some stays in lane 5 (the fixes' evidence), and lane 7,
  // which neither the row nor the fixes favour, gets little. With a tight prior (a robot measured the bias)
  // the fixes rule out a 1.5 m shift and the row cannot move the belief.
  auto map = polytunnel();
  const NodeIndex here = *map->index("r5_5"), row = *map->index("r6_5"), beyond = *map->index("r7_5");
  auto afterReport = [&](int sweeps, double prior_variance) {
    TpfParams p = staticParams(1000);
    p.gnss_bias_state = true;
    p.lane_swap_rate = 0.0;  // the moves of the reported row only
    p.jsd_monitor = false;
    p.lane_evidence_sweeps = sweeps;
    p.lane_evidence_projection = false;  // the swap moves alone (the projection: the next test)
    TopologicalParticleFilter f(map, p, 23);
    EXPECT_TRUE(f.update(obsAt(0.0, {here}, {1.0}, true, "uwb")).ok());
    for (int k = 1; k <= 60; ++k)
      EXPECT_TRUE(f.update(biasedFix(*map, k, map->position2d(here), 9.0, {0.0, 0.0}, prior_variance,
                                     2.0 * 6.25 / 300.0))
                      .ok());
    core::Observation reported = obsAt(61.0, {}, {}, true, "reported_row");
    for (NodeIndex n = 0; n < map->numNodes(); ++n) {
      reported.nodes.push_back(n);
      reported.likelihood.push_back(map->lane(n) == map->lane(row) ? 1.0 : 0.2);
    }
    EXPECT_TRUE(f.update(reported).ok());
    return std::make_tuple(laneMass(*map, f.belief(), here), laneMass(*map, f.belief(), row),
                           laneMass(*map, f.belief(), beyond));
  };
  const auto [off_here, off_row, off_beyond] = afterReport(0, 10.25);
  (void)off_beyond;
  EXPECT_GT(off_here, 0.999);
  EXPECT_LT(off_row, 1e-3);
  const auto [on_here, on_row, on_beyond] = afterReport(4, 10.25);
  EXPECT_GT(on_row, 0.4);  // measured 0.51 (lane 5 0.19, lane 7 0.04, lane 4 the rest)
  EXPECT_GT(on_row, 2.0 * on_here);
  EXPECT_GT(on_here, 0.05);
  EXPECT_LT(on_beyond, 0.1);
  const auto [tight_here, tight_row, tight_beyond] = afterReport(4, 0.05);
  EXPECT_GT(tight_here, 0.95);
  EXPECT_LT(tight_row + tight_beyond, 0.05);
}

TEST(TpfGnssBias, AReportedRowMovesTheParticlesAcrossKeepingWhereAlongTheLane) {
  // A minute of phone fixes on lane 5 holds every particle there. The picker reports lane 7, two lanes over
  // (likelihood 1 there, 0.2 elsewhere). With the projection each particle moves across into lane 7 with
  // probability 1 - 0.2, to the same place along it: lane 7 holds ~0.8, lane 5 keeps ~0.2, and the moved mass
  // sits across from where the fixes put the picker, not spread along the row. Then the fixes go on: with the
  // phone's wide prior they cannot tell the lanes apart and the row holds; with a tight prior (a robot
  // measured the bias) they rule out the 3 m shift and take the belief back to lane 5. Weighting alone
  // (projection off) leaves lane 7 empty.
  auto map = polytunnel();
  const NodeIndex here = *map->index("r5_5"), row = *map->index("r7_5");
  struct Masses {
    double here_lane, row_lane, row_node_and_neighbours, row_lane_later;
  };
  auto afterReport = [&](bool projection, double prior_variance) {
    TpfParams p = staticParams(1000);
    p.gnss_bias_state = true;
    p.lane_swap_rate = 0.0;  // the row's moves only
    p.jsd_monitor = false;
    p.lane_evidence_projection = projection;
    TopologicalParticleFilter f(map, p, 29);
    EXPECT_TRUE(f.update(obsAt(0.0, {here}, {1.0}, true, "uwb")).ok());
    auto fix = [&](double t) {
      return biasedFix(*map, t, map->position2d(here), 9.0, {0.0, 0.0}, prior_variance, 2.0 * 6.25 / 300.0);
    };
    for (int k = 1; k <= 60; ++k) EXPECT_TRUE(f.update(fix(k)).ok());
    core::Observation reported = obsAt(61.0, {}, {}, true, "reported_row");
    for (NodeIndex n = 0; n < map->numNodes(); ++n) {
      reported.nodes.push_back(n);
      reported.likelihood.push_back(map->lane(n) == map->lane(row) ? 1.0 : 0.2);
    }
    EXPECT_TRUE(f.update(reported).ok());
    Masses m{};
    m.here_lane = laneMass(*map, f.belief(), here);
    m.row_lane = laneMass(*map, f.belief(), row);
    for (std::size_t j = 0; j < f.belief().nodes.size(); ++j) {
      const NodeIndex n = f.belief().nodes[j];
      if (map->lane(n) == map->lane(row) && (map->position2d(n) - map->position2d(row)).norm() < 3.5)
        m.row_node_and_neighbours += f.belief().masses[j];
    }
    for (int k = 62; k <= 91; ++k) EXPECT_TRUE(f.update(fix(k)).ok());
    m.row_lane_later = laneMass(*map, f.belief(), row);
    return m;
  };
  const Masses off = afterReport(false, 10.25);
  EXPECT_LT(off.row_lane, 1e-3);
  EXPECT_GT(off.here_lane, 0.999);
  const Masses wide = afterReport(true, 10.25);
  EXPECT_NEAR(wide.row_lane, 0.8, 0.05);
  EXPECT_NEAR(wide.here_lane, 0.2, 0.05);
  EXPECT_GT(wide.row_node_and_neighbours, 0.9 * wide.row_lane);  // across from the fixes, not along the row
  EXPECT_GT(wide.row_lane_later, 0.7);  // measured 0.805: the fixes cannot tell the lanes apart
  const Masses tight = afterReport(true, 0.05);
  EXPECT_NEAR(tight.row_lane, 0.8, 0.05);
  EXPECT_LT(tight.row_lane_later, 0.05);
}

TEST(TpfGnssBias, AConstantBiasOfALaneSpacingDoesNotMoveTheLane) {
  // The picker stands in lane 5 (a sighting put the belief there); its phone's fixes sit on lane 6, a
  // constant bias of one lane spacing, reported with the phone's 3 m. Fused as independent fixes (bias state
  // off), every fix favours lane 6 a little and particles that jump there (p_rj) take over; with the bias
  // state, the particles of lane 5 learn the bias and predict every fix, and a jumper, starting from the 3.2
  // m prior, cannot.
  auto map = polytunnel();
  const NodeIndex here = *map->index("r5_5"), there = *map->index("r6_5");
  const Eigen::Vector2d bias = map->position2d(there) - map->position2d(here);
  auto laneShare = [&](bool bias_state) {
    TpfParams p = staticParams(500);
    p.gnss_bias_state = bias_state;
    p.unconnected_jump_probability = 0.01;
    p.entropy_gate = false;
    TopologicalParticleFilter f(map, p, 17);
    EXPECT_TRUE(f.update(obsAt(0.0, {here}, {1.0}, true, "uwb")).ok());
    for (int k = 1; k <= 300; ++k)
      EXPECT_TRUE(f.update(biasedFix(*map, k, map->position2d(here) + bias, 9.0, {0.0, 0.0}, 10.25,
                                     2.0 * 6.25 / 300.0))
                      .ok());
    double share = 0.0;
    for (std::size_t j = 0; j < f.belief().nodes.size(); ++j)
      if (map->lane(f.belief().nodes[j]) == map->lane(here)) share += f.belief().masses[j];
    return share;
  };
  EXPECT_GT(laneShare(true), 0.9);
  EXPECT_LT(laneShare(false), 0.5);
}

TEST(TpfStanding, TheChainOfStopsAndStartsAndAStandingParticleStays) {
  // stand_rate s, walk_rate w, every particle walking at first, steps of 1 s: a step stops a walking particle
  // with p_s = 1 - exp(-s) and starts a standing one with p_w = 1 - exp(-w), so after k steps the standing
  // share is p_s / (p_s + p_w) (1 - (1 - p_s - p_w)^k). A standing particle does not jump.
  auto map = laneMap(40, 3.0);
  TpfParams p = staticParams(20000);
  p.velocity_follows_edge = true;
  p.velocity_init_mean = 0.5;
  p.stand_rate = 0.05;
  p.walk_rate = 0.15;
  TopologicalParticleFilter f(map, p, 11);
  ASSERT_TRUE(f.update(obsAt(0.0, {2}, {1.0})).ok());
  for (int k = 1; k <= 10; ++k) ASSERT_TRUE(f.predictTo(k));
  std::size_t standing = 0;
  for (const auto& q : f.particles()) standing += q.standing ? 1 : 0;
  const double p_s = 1.0 - std::exp(-0.05), p_w = 1.0 - std::exp(-0.15);
  EXPECT_NEAR(static_cast<double>(standing) / f.particles().size(),
              p_s / (p_s + p_w) * (1.0 - std::pow(1.0 - p_s - p_w, 10)), 0.01);

  TpfParams still = staticParams(2000);
  still.velocity_init_mean = 0.5;
  still.stand_rate = 20.0;  // nearly every particle stops in the first step, before it can jump
  still.walk_rate = 1e-9;
  TopologicalParticleFilter g(map, still, 12);
  ASSERT_TRUE(g.update(obsAt(0.0, {2}, {1.0})).ok());
  ASSERT_TRUE(g.predictTo(0.5));
  ASSERT_TRUE(g.predictTo(60.0));  // walking at 0.5 m/s a particle would be ~10 nodes on
  std::size_t stayed = 0;
  for (const auto& q : g.particles()) {
    if (q.standing) EXPECT_EQ(q.node, 2u);
    stayed += q.standing && q.node == 2 ? 1 : 0;
  }
  EXPECT_GT(stayed, g.particles().size() * 99 / 100);
  EXPECT_EQ(TpfParams::presetForMethod("paper_tpf").stand_rate, 0.0);  // the paper's particles always walk
}

TEST(TpfStanding, AParticleThatStopsInTheLaneItChangedIntoHasArrived) {
  // Particles leave lane 5 at its far end and follow the headland path into lane 4 or 6 (it ends one node
  // inside the lane). One that stops in the new lane before the path's end has arrived there: no path left,
  // its side remembered. Left on the path it stayed out of the lane swaps and the shared lane masses while it
  // stood.
  auto map = polytunnel();
  TpfParams p = staticParams(4000);
  p.velocity_follows_edge = true;
  p.lane_change_model = true;
  p.velocity_init_mean = 0.0;
  p.velocity_init_variance = 0.25;  // every direction; about a quarter walk on towards the headland
  p.stand_rate = 0.1;
  p.walk_rate = 1e-9;
  TopologicalParticleFilter f(map, p, 21);
  const NodeIndex end = *map->index("r5_9");
  ASSERT_TRUE(f.update(obsAt(0.0, {end}, {1.0})).ok());
  std::size_t arrived = 0;
  for (int k = 1; k <= 40; ++k) {
    ASSERT_TRUE(f.predictTo(0.5 * k));
    for (const auto& q : f.particles())
      if (q.standing && map->lane(q.node) != topology::kNoLane && map->lane(q.node) != map->lane(end)) {
        EXPECT_EQ(q.lane_change, 0u) << map->node(q.node).name;
        arrived += q.last_lane_change != 0 ? 1 : 0;  // came by a lane-change path (the leak takes others)
      }
  }
  EXPECT_GT(arrived, 0u);
}

TEST(TpfStanding, APickerStandingNearALaneEndIsNamedInTheLane) {
  // A picker walks lane 5 (phone fixes, 3.2 m prior, a slowly wandering 1-2 m error) and stands 300 s at
  // r5_8, 6 m from the headland. Every particle walking, the cloud that best explains a standing picker near
  // a lane end bounces about the headland, where a particle can step either way, while in the lane it walks
  // on past the fixes: the headland was named for minutes. Particles that stand stay in the lane.
  auto map = polytunnel();
  const NodeIndex start = *map->index("r5_0"), stand = *map->index("r5_8");
  const Eigen::Vector2d a = map->position2d(start), b = map->position2d(stand);
  const double walk_s = (b - a).norm() / 0.5;
  auto inLane = [&](double stand_rate, std::uint64_t seed) {
    TpfParams p;  // the product's defaults
    p.num_particles = 1000;
    p.stand_rate = stand_rate;
    TopologicalParticleFilter f(map, p, seed);
    EXPECT_TRUE(f.update(obsAt(0.0, {start}, {1.0}, true, "uwb")).ok());
    int named = 0, samples = 0;
    for (int k = 1; k <= static_cast<int>(walk_s) + 300; ++k) {
      const double t = k;
      const bool walking = t < walk_s;
      const Eigen::Vector2d truth = walking ? Eigen::Vector2d(a + (b - a) * (t / walk_s)) : b;
      const Eigen::Vector2d error(0.8 * std::sin(t / 70.0), 1.5 * std::cos(t / 50.0));
      core::Observation o = biasedFix(*map, t, truth + error, 9.0, {0.0, 0.0}, 10.25, 2.0 * 6.25 / 300.0);
      o.velocity = walking ? Eigen::Vector2d((b - a).normalized() * 0.5) : Eigen::Vector2d(0.0, 0.0);
      EXPECT_TRUE(f.update(o).ok());
      if (t >= walk_s + 60.0) {
        ++samples;
        named += map->lane(f.belief().map_node) == map->lane(stand) ? 1 : 0;
      }
    }
    return static_cast<double>(named) / samples;
  };
  double walking_only = 0.0, with_standing = 0.0;
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    walking_only += inLane(0.0, seed) / 4.0;
    with_standing += inLane(TpfParams().stand_rate, seed) / 4.0;
  }
  EXPECT_GT(with_standing, 0.9) << "walking only: " << walking_only;
  EXPECT_LT(walking_only, with_standing - 0.2) << "with standing: " << with_standing;
  std::cout << "lane named while standing: walking only " << walking_only << ", with standing "
            << with_standing << std::endl;
}

// A map edited at run time: the particles move onto the new map (removed node: the nearest), velocities and
// bias states kept, the belief names only nodes of the new map.
TEST(TpfAnonymous, AnUnidentifiedPersonTheParticlesBarelyExplainIsSomeoneElse) {
  // A thousand particles from a first fix, a few of them (~1 %) 108 m away at n38. A person naming nobody is
  // seen at n37, 3 m beyond them: only its likelihood's tail (0.01 of its peak) reaches them, every other
  // particle has 0. Weighed as the paper weighs every LiDAR person, the few strays take the whole cloud (what
  // a run traced: a caller's belief 100 m off, then the person beside the robot named the caller); with
  // anonymous_min_support it is someone else and the belief stays. The same person identified as this
  // picker is fused (the paper's monitor redraws the cloud around it).
  auto map = laneMap(40, 3.0);
  auto massNearThePerson = [&](double min_support, bool identifying) {
    TpfParams p = staticParams(1000);
    p.anonymous_min_support = min_support;
    TopologicalParticleFilter f(map, p, 5);
    EXPECT_TRUE(f.update(obsAt(0.0, {2, 38}, {0.9, 0.1})).ok());  // drawn from it, then weighed by it
    const double before = nodeFractions(f.particles())[38];
    EXPECT_GT(before, 0.0);
    EXPECT_LT(before, 0.05);
    EXPECT_TRUE(f.update(obsAt(1.0, {37, 38}, {1.0, 0.01}, identifying, "lidar")).ok());
    auto fractions = nodeFractions(f.particles());
    return fractions[37] + fractions[38];
  };
  EXPECT_GT(massNearThePerson(0.0, false), 0.99);  // the paper: collapsed onto the strays
  EXPECT_LT(massNearThePerson(0.001, false), 0.05);
  EXPECT_GT(massNearThePerson(0.001, true), 0.99);
  EXPECT_EQ(TpfParams::presetForMethod("paper_tpf").anonymous_min_support, 0.0);
  EXPECT_GT(TpfParams().anonymous_min_support, 0.0);
  TpfParams bad;
  bad.anonymous_min_support = 1.5;
  EXPECT_NE(bad.validate().find("anonymous_min_support"), std::string::npos);
}

TEST(TpfAnonymous, AnUnidentifiedPersonPullsAsMuchMassAsItsAssociationProbability) {
  // Half the particles at n2, half at n20 (a first fix of two equal modes). A person naming nobody is seen at
  // n20, and the association says it is this picker with probability rho. The PDA update (Bar-Shalom and Tse
  // 1975) mixes "this picker" (all mass to n20) and "someone else" (the belief as it was) at rho : 1 - rho,
  // so n20 ends with rho + (1 - rho) m, m its mass before (0.6 for rho 0.2 and m 0.5). Taken as certain (the
  // paper, or the option off) it takes it all; an identifying observation ignores the probability.
  auto map = laneMap(40, 3.0);
  struct Masses {
    double before, after;
  };
  auto atThePerson = [&](bool weigh, double rho, bool identifying, bool weigh_named = false) {
    TpfParams p = staticParams(2000);
    p.weigh_anonymous_by_association = weigh;
    p.weigh_named_by_association = weigh_named;
    TopologicalParticleFilter f(map, p, 9);
    EXPECT_TRUE(f.update(obsAt(0.0, {2, 20}, {0.5, 0.5})).ok());
    Masses m{nodeFractions(f.particles())[20], 0.0};
    EXPECT_NEAR(m.before, 0.5, 0.05);
    EXPECT_TRUE(f.update(obsAt(1.0, {20}, {1.0}, identifying, "lidar"), rho).ok());
    m.after = nodeFractions(f.particles())[20];
    return m;
  };
  for (double rho : {0.2, 0.7}) {
    const Masses m = atThePerson(true, rho, false);
    EXPECT_NEAR(m.after, rho + (1.0 - rho) * m.before, 0.04) << rho;
  }
  EXPECT_GT(atThePerson(true, 1.0, false).after, 0.99);
  EXPECT_GT(atThePerson(false, 0.2, false).after, 0.99);  // the option off: certain
  EXPECT_GT(atThePerson(true, 0.2, true).after, 0.99);    // identified: certain
  // weigh_named_by_association: a person the association named this picker at 0.8 pulls 0.8 of the mass.
  const Masses named = atThePerson(true, 0.8, true, true);
  EXPECT_NEAR(named.after, 0.8 + 0.2 * named.before, 0.04);
  EXPECT_GT(atThePerson(false, 0.8, false, true).after,
            0.99);  // anonymous with only the named option: certain
  EXPECT_FALSE(TpfParams::presetForMethod("paper_tpf").weigh_anonymous_by_association);
  EXPECT_FALSE(TpfParams::presetForMethod("paper_tpf").weigh_named_by_association);
  EXPECT_TRUE(TpfParams().weigh_anonymous_by_association);
}

TEST(TpfMapUpdate, ParticlesFollowTheEditedMap) {
  auto before = polytunnel();
  TopologicalParticleFilter f(before, TpfParams(), 7);
  const NodeIndex at = before->laneNodes(1)[2];
  ASSERT_TRUE(f.update(obsAt(1.0, {at}, {1.0})).ok());
  std::vector<topology::Node> nodes = before->nodes();
  std::vector<topology::EdgeSpec> edges;
  const std::string gone = before->node(at).name;
  for (const auto& e : before->edges())
    if (e.source != at && e.target != at)
      edges.push_back({e.id, before->node(e.source).name, before->node(e.target).name, e.action});
  nodes.erase(nodes.begin() + at);
  auto after = std::make_shared<const topology::TopologicalMap>(
      topology::TopologicalMap::build("edited", nodes, edges));
  const topology::MapChange change = topology::compareMaps(*before, *after);
  std::vector<float> vx;
  for (const Particle& p : f.particles()) vx.push_back(p.vx);
  f.adoptMap(after, change.old_to_new);
  EXPECT_EQ(&f.map(), after.get());
  ASSERT_EQ(f.particles().size(), vx.size());
  for (std::size_t i = 0; i < vx.size(); ++i) {
    EXPECT_LT(f.particles()[i].node, after->numNodes());
    EXPECT_EQ(f.particles()[i].vx, vx[i]);
  }
  double mass = 0.0;
  for (std::size_t k = 0; k < f.belief().nodes.size(); ++k) mass += f.belief().masses[k];
  EXPECT_NEAR(mass, 1.0, 1e-9);
  // The mass that sat on the removed node is at the node nearest to it.
  EXPECT_EQ(f.belief().map_node, change.old_to_new[at]);
  EXPECT_LT((after->position2d(f.belief().map_node) - before->position2d(at)).norm(), 3.0);
  EXPECT_FALSE(after->index(gone).has_value());
  // It goes on filtering on the new map.
  EXPECT_TRUE(f.update(obsAt(2.0, {change.old_to_new[at]}, {1.0})).ok());
  EXPECT_THROW(f.adoptMap(after, {}), std::invalid_argument);
}
