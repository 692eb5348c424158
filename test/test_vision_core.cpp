// sensors_vision core: Munkres vs brute force, bearing vs hand-computed values, Algorithm 3 segmentation on a
// hand-built scan, the cluster tracker's id stability / hysteresis, the fusion cone. No roscore.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "picker_localisation/sensors_vision/cluster_tracker.h"
#include "picker_localisation/sensors_vision/leg_detector.h"
#include "picker_localisation/sensors_vision/leg_detector_node_options.h"
#include "picker_localisation/sensors_vision/leg_pipeline.h"
#include "picker_localisation/sensors_vision/lidar_camera_fusion.h"
#include "picker_localisation/sensors_vision/munkres.h"
#include "picker_localisation/sensors_vision/person_box_detector.h"
#include "picker_localisation/topology/synthetic_map.h"

using namespace picker_localisation;
using namespace picker_localisation::vision;

namespace {

// Minimum over all injective maps of the smaller side into the larger (permutations).
double bruteForce(const Eigen::MatrixXd& c) {
  const bool t = c.rows() > c.cols();
  const Eigen::MatrixXd m = t ? Eigen::MatrixXd(c.transpose()) : c;
  std::vector<int> cols(m.cols());
  std::iota(cols.begin(), cols.end(), 0);
  double best = 1e18;
  do {
    double s = 0;
    for (int r = 0; r < m.rows(); ++r) s += m(r, cols[r]);
    best = std::min(best, s);
  } while (std::next_permutation(cols.begin(), cols.end()));
  return best;
}

}  // namespace

TEST(Munkres, MatchesBruteForceOnRandomRectangularMatrices) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> u(0.0, 10.0);
  std::uniform_int_distribution<int> size(1, 6);
  for (int trial = 0; trial < 300; ++trial) {
    const int n = size(rng), m = size(rng);
    Eigen::MatrixXd c(n, m);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < m; ++j) c(i, j) = trial % 3 == 0 ? std::floor(u(rng)) : u(rng);  // ties too
    const auto a = solveAssignment(c);
    ASSERT_EQ(static_cast<int>(a.size()), n);
    int assigned = 0;
    std::vector<int> seen;
    for (int col : a)
      if (col >= 0) {
        ++assigned;
        seen.push_back(col);
      }
    std::sort(seen.begin(), seen.end());
    EXPECT_TRUE(std::adjacent_find(seen.begin(), seen.end()) == seen.end()) << "column used twice";
    EXPECT_EQ(assigned, std::min(n, m));
    EXPECT_NEAR(assignmentCost(c, a), bruteForce(c), 1e-9) << "trial " << trial;
  }
}

TEST(Munkres, HandExampleAndEmpty) {
  Eigen::MatrixXd c(3, 3);
  c << 4, 1, 3, 2, 0, 5, 3, 2, 2;  // optimum 1 + 2 + 2 = 5: (0,1) (1,0) (2,2)
  EXPECT_EQ(solveAssignment(c), (std::vector<int>{1, 0, 2}));
  EXPECT_TRUE(solveAssignment(Eigen::MatrixXd(0, 3)).empty());
  EXPECT_EQ(solveAssignment(Eigen::MatrixXd(2, 0)), (std::vector<int>{-1, -1}));
}

TEST(Bearing, HandComputedValues) {
  CameraIntrinsics k{500.0, 320.0, 640};
  // Column 320 is the principal point: straight ahead.
  EXPECT_NEAR(bearingFromColumn(320.0, k), 0.0, 1e-12);
  // Column 820 - 500 px = 320 - 500 = -180... use u = 820? Outside; u = 0: atan(320 / 500) = 0.5693 rad (left).
  EXPECT_NEAR(bearingFromColumn(0.0, k), 0.569313191, 1e-6);
  // u = 820 would be right; u = 570: atan(-250 / 500) = -0.463647609 rad (right of centre).
  EXPECT_NEAR(bearingFromColumn(570.0, k), -0.463647609, 1e-6);
  // Box centre column = 100 + 240 / 2 = 220: atan(100 / 500) = 0.197395560.
  EXPECT_NEAR(bearingFromBox(cv::Rect(100, 50, 240, 300), k), 0.197395560, 1e-6);
  // Eq. 1 with the field of view: 90 deg fov, 640 px, u = 0 -> atan(2 * 320 * 1 / 640) = pi / 4.
  EXPECT_NEAR(bearingFromColumnFov(0.0, M_PI / 2, 640), M_PI / 4, 1e-12);
  // Both forms agree when fx = (w / 2) / tan(fov / 2) and cx = w / 2.
  const double fov = 1.2;
  CameraIntrinsics k2{320.0 / std::tan(0.6), 320.0, 640};
  for (double u : {0.0, 100.0, 333.0, 639.0}) EXPECT_NEAR(bearingFromColumn(u, k2), bearingFromColumnFov(u, fov, 640), 1e-12);
  EXPECT_THROW(bearingFromColumn(1.0, CameraIntrinsics{0.0, 1.0, 2}), std::invalid_argument);
}

namespace {

// A scan with beams 1 degree apart; `objects` are (first beam, last beam, range) blocks, the rest no return.
core::LaserScan blockScan(const std::vector<std::tuple<int, int, float>>& objects, int beams = 180) {
  core::LaserScan s;
  s.angle_min = -M_PI / 2;
  s.angle_increment = M_PI / 180.0;
  s.range_min = 0.05;
  s.range_max = 10.0;
  s.ranges.assign(beams, std::numeric_limits<float>::infinity());
  for (const auto& [a, b, r] : objects)
    for (int i = a; i <= b; ++i) s.ranges[i] = r;
  return s;
}

}  // namespace

TEST(Segmentation, JumpDistanceSplitsAndRichnessFilters) {
  // Beams 1 deg apart at 2 m are 0.035 m apart. Block A: beams 10-14 at 2 m; block B: 15-20 at 2.5 m (jump 0.5 m
  // > d_c); block C: 40-41 (2 points < m_c = 3, dropped); block D: 60-70 at 3 m.
  const auto scan = blockScan({{10, 14, 2.0f}, {15, 20, 2.5f}, {40, 41, 2.0f}, {60, 70, 3.0f}});
  const auto clusters = segmentScan(scan);
  ASSERT_EQ(clusters.size(), 3u);
  EXPECT_EQ(clusters[0].points.size(), 5u);
  EXPECT_EQ(clusters[0].first_beam, 10u);
  EXPECT_EQ(clusters[1].points.size(), 6u);
  EXPECT_EQ(clusters[2].points.size(), 11u);
  // Centroid of block D: points on an arc at 3 m centred on beam 65 (angle -90 + 65 = -25 deg).
  const Eigen::Vector2d c = clusters[2].centroid();
  EXPECT_NEAR(std::atan2(c.y(), c.x()), -25.0 * M_PI / 180.0, 1e-9);
  // NaN / inf / below range_min are no returns: an all-invalid scan has no clusters.
  auto empty = blockScan({});
  empty.ranges[5] = std::nanf("");
  empty.ranges[6] = 0.01f;
  EXPECT_TRUE(segmentScan(empty).empty());
  core::LaserScan zero;
  EXPECT_TRUE(segmentScan(zero).empty());
}

TEST(LegPairing, NearestLegsPairedSingleLegsKept) {
  std::vector<Leg> legs(3);
  legs[0].position = {2.0, 0.0};
  legs[0].confidence = 0.8;
  legs[1].position = {2.0, 0.3};
  legs[1].confidence = 0.6;
  legs[2].position = {5.0, 0.0};
  legs[2].confidence = 0.9;
  LegDetectorOptions o;
  const auto people = pairLegs(legs, o);
  ASSERT_EQ(people.size(), 2u);
  EXPECT_NEAR(people[0].position.y(), 0.15, 1e-12);
  EXPECT_NEAR(people[0].confidence, 0.7, 1e-12);
  EXPECT_EQ(people[1].leg_b, -1);
  EXPECT_NEAR(people[1].confidence, 0.45, 1e-12);
  o.single_leg_people = false;
  EXPECT_EQ(pairLegs(legs, o).size(), 1u);
}

TEST(ClusterTracker, StableIdsHysteresisAndGating) {
  ClusterTrackerOptions o;
  o.gate_distance = 0.5;
  o.hits_to_confirm = 3;
  o.misses_to_delete = 2;
  ClusterTracker tracker(o);
  // Two objects walking in parallel 1 m apart, 0.1 m per scan; their order in the detection list swaps.
  int id_a = -1, id_b = -1;
  for (int k = 0; k < 6; ++k) {
    const Eigen::Vector2d a(0.1 * k, 0.0), b(0.1 * k, 1.0);
    std::vector<Eigen::Vector2d> det = (k % 2) ? std::vector<Eigen::Vector2d>{b, a} : std::vector<Eigen::Vector2d>{a, b};
    tracker.update(0.1 * k, det);
    const auto confirmed = tracker.confirmedTracks();
    if (k < 2) EXPECT_TRUE(confirmed.empty()) << "confirmed before T_a hits";
    if (k >= 2) {
      ASSERT_EQ(confirmed.size(), 2u);
      for (const auto& t : confirmed) {
        const bool is_a = std::abs(t.position.y()) < 0.5;
        int& id = is_a ? id_a : id_b;
        if (id < 0) id = t.id;
        EXPECT_EQ(t.id, id) << "id changed at scan " << k;
      }
    }
  }
  EXPECT_NE(id_a, id_b);
  EXPECT_NEAR(tracker.confirmedTracks()[0].velocity.x(), 1.0, 1e-6);  // 0.1 m per 0.1 s
  // A detection beyond the gate starts a new tentative track instead of moving A.
  tracker.update(0.6, {Eigen::Vector2d(0.5, 1.0), Eigen::Vector2d(2.0, 0.0)});
  bool a_alive = false;
  for (const auto& t : tracker.tracks()) a_alive = a_alive || (t.id == id_a && t.misses == 1 && t.position.x() < 0.6);
  EXPECT_TRUE(a_alive);
  // A misses a second scan: removed (T_o = 2); B keeps its id.
  tracker.update(0.7, {Eigen::Vector2d(0.6, 1.0)});
  for (const auto& t : tracker.tracks()) EXPECT_NE(t.id, id_a);
  ASSERT_EQ(tracker.confirmedTracks().size(), 1u);
  EXPECT_EQ(tracker.confirmedTracks()[0].id, id_b);
  // Empty scans are fine; stamps going backwards do not corrupt velocity.
  tracker.update(0.65, {Eigen::Vector2d(0.7, 1.0)});
  EXPECT_TRUE(tracker.confirmedTracks()[0].velocity.allFinite());
  tracker.update(0.8, {});
  tracker.update(0.9, {});
  EXPECT_TRUE(tracker.tracks().empty());
}

TEST(ClusterTracker, WindowVelocityIsTheWalkNotTheLegSwing) {
  // A person walks +x at 0.5 m/s, seen at 10 Hz; the leg pair's centroid swings +-0.15 m across and along the
  // walk from scan to scan. The scan-to-scan velocity is mostly the swing (3 m/s); the track's displacement
  // over velocity_window (2 s) is the walk. None before the track spans half the window; a stamp going back
  // starts the window again.
  using picker_localisation::vision::ClusterTracker;
  using picker_localisation::vision::ClusterTrackerOptions;
  ClusterTrackerOptions o;
  o.velocity_window = 2.0;
  ClusterTracker tracker(o);
  double worst_scan_to_scan = 0.0;
  for (int k = 0; k <= 60; ++k) {
    const double t = 0.1 * k, swing = (k % 2 ? 0.15 : -0.15);
    const auto& tracks = tracker.update(t, {Eigen::Vector2d(0.5 * t + swing, swing)});
    ASSERT_EQ(tracks.size(), 1u);
    const auto& tr = tracks.front();
    if (t < 0.95) {
      EXPECT_FALSE(tr.has_window_velocity) << t;
    } else if (t > 1.05) {
      ASSERT_TRUE(tr.has_window_velocity) << t;
      EXPECT_NEAR(tr.window_velocity.x(), 0.5, 0.35 / (std::min(t, 2.0))) << t;  // the swing over the span
      EXPECT_NEAR(tr.window_velocity.y(), 0.0, 0.35 / (std::min(t, 2.0))) << t;
      worst_scan_to_scan = std::max(worst_scan_to_scan, std::abs(tr.velocity.y()));
    }
    if (t >= 2.0) EXPECT_LE(tr.recent.size(), 22u);  // the window, not the track's life
  }
  EXPECT_GT(worst_scan_to_scan, 1.0);                                    // what the window is for
  const auto& back = tracker.update(5.0, {Eigen::Vector2d(2.9, -0.1)});  // last at 6.0 s
  ASSERT_EQ(back.size(), 1u);
  EXPECT_FALSE(back.front().has_window_velocity);
  ClusterTrackerOptions none;
  none.velocity_window = 0.0;
  ClusterTracker off(none);
  for (int k = 0; k <= 30; ++k)
    EXPECT_FALSE(off.update(0.1 * k, {Eigen::Vector2d(0.05 * k, 0.0)}).front().has_window_velocity);
}

TEST(LidarCameraFusion, NearestClusterInConeIsPromoted) {
  LidarCameraFusionOptions o;
  o.cone_margin = 0.0;
  o.promote_after = 2;
  o.demote_after = 2;
  LidarCameraFusion fusion(o);
  std::vector<FusionCandidate> c(3);
  c[0].position = {4.0, 0.0};  // bearing 0, far
  c[0].track_id = 7;
  c[0].confidence = 0.3;
  c[1].position = {2.0, 0.05};  // bearing 0.025, near: the one picked
  c[1].track_id = 8;
  c[1].confidence = 0.3;
  c[2].position = {2.0, 2.0};  // bearing 0.785, outside the cone
  c[2].track_id = 9;
  BearingCone cone{0.0, 0.1, 0.9};
  EXPECT_EQ(fusion.nearestInCone(cone, c), 1);
  EXPECT_EQ(fusion.nearestInCone(BearingCone{M_PI, 0.1, 0.9}, c), -1);  // behind the camera
  auto f = fusion.fuse(c, {cone}, true);
  EXPECT_TRUE(f[1].camera_confirmed);
  EXPECT_FALSE(f[0].camera_confirmed);
  EXPECT_GT(f[1].confidence, f[0].confidence);
  EXPECT_FALSE(fusion.promoted(8));
  fusion.fuse(c, {cone}, true);
  EXPECT_TRUE(fusion.promoted(8));
  // LiDAR-only frames keep the promotion; camera frames without a match demote after m_r = 2.
  EXPECT_TRUE(fusion.fuse(c, {}, false)[1].camera_confirmed);
  fusion.fuse(c, {}, true);
  EXPECT_TRUE(fusion.promoted(8));
  fusion.fuse(c, {}, true);
  EXPECT_FALSE(fusion.promoted(8));
}

TEST(NonMaximumSuppression, KeepsBestOfOverlappingBoxes) {
  std::vector<PersonBox> boxes{{cv::Rect(0, 0, 100, 200), 0.5}, {cv::Rect(10, 10, 100, 200), 0.9},
                               {cv::Rect(300, 0, 100, 200), 0.4}};
  const auto kept = suppressOverlaps(boxes, 0.4);
  ASSERT_EQ(kept.size(), 2u);
  EXPECT_DOUBLE_EQ(kept[0].confidence, 0.9);
  EXPECT_EQ(kept[1].box.x, 300);
}

#include "picker_localisation/sensors_vision/cloud3d_person_detector.h"

namespace {

void addBox(pcl::PointCloud<pcl::PointXYZ>& cloud, Eigen::Vector3d lo, Eigen::Vector3d hi, double step) {
  for (double x = lo.x(); x <= hi.x() + 1e-9; x += step)
    for (double y = lo.y(); y <= hi.y() + 1e-9; y += step)
      for (double z = lo.z(); z <= hi.z() + 1e-9; z += step) cloud.push_back(pcl::PointXYZ(x, y, z));
}

}  // namespace

TEST(Cloud3dPersonDetector, PersonSizedClusterAboveGroundOnly) {
  pcl::PointCloud<pcl::PointXYZ> cloud;
  addBox(cloud, {-5, -5, 0}, {5, 5, 0}, 0.1);                 // level ground
  addBox(cloud, {2.0, 1.0, 0.05}, {2.3, 1.4, 1.75}, 0.05);    // a person: 0.3 x 0.4 x 1.7 m
  addBox(cloud, {-3.0, 2.0, 0.05}, {-2.5, 2.5, 0.5}, 0.05);   // a bush, too low
  addBox(cloud, {0.0, -4.0, 0.05}, {4.0, -3.9, 2.0}, 0.05);   // a wall, too wide
  cloud.push_back(pcl::PointXYZ(std::nanf(""), 0, 0));        // invalid points are skipped
  const auto people = Cloud3dPersonDetector().detect(cloud);
  ASSERT_EQ(people.size(), 1u);
  EXPECT_NEAR(people[0].centroid.x(), 2.15, 0.05);
  EXPECT_NEAR(people[0].centroid.y(), 1.2, 0.05);
  EXPECT_NEAR(people[0].extent.z(), 1.7, 0.1);
  EXPECT_GT(people[0].confidence, 0.5);
  EXPECT_TRUE(Cloud3dPersonDetector().detect(pcl::PointCloud<pcl::PointXYZ>()).empty());
}

// The leg pipeline's options schema (shared by the leg_detector node and the offline runner).
TEST(LegPipelineOptions, ReadsKeysRejectsBadValuesAndNamesUnknownKeys) {
  using picker_localisation::vision::LegDetectorNodeOptions;
  using picker_localisation::vision::LegPipelineOptions;
  std::vector<std::string> unknown;
  const LegPipelineOptions o =
      LegDetectorNodeOptions::fromYaml(
          YAML::Load("{leg_threshold: 0.3, tentative_misses: 2, position_sigma: 0.2, scan_topics: [a], "
                     "leg_treshold: 0.5, detections_topic: cam}"),
          &unknown)
          .pipeline;
  EXPECT_DOUBLE_EQ(o.detector.leg_threshold, 0.3);
  EXPECT_EQ(o.tracker.tentative_misses, 2);
  EXPECT_DOUBLE_EQ(o.position_sigma, 0.2);
  EXPECT_DOUBLE_EQ(o.tracker.velocity_window, 2.0);  // default
  EXPECT_TRUE(o.camera_fusion);  // a detections topic enables fusion, as in the node
  ASSERT_EQ(unknown.size(), 1u);  // scan_topics is a node key: known
  EXPECT_NE(unknown[0].find("'leg_treshold'"), std::string::npos) << unknown[0];
  EXPECT_NE(unknown[0].find("'leg_threshold'"), std::string::npos) << unknown[0];
  for (const char* bad : {"{leg_threshold: -1}", "{min_cluster_points: -3}", "{position_sigma: 0}",
                          "{hits_to_confirm: 0}", "{leg_threshold: abc}", "{negative_p_detect: 1.0}",
                          "{negative_range_max: 2.0}", "{negative_period: -1}", "{negative_clearance: -0.5}",
                          "{velocity_window: -1}", "{velocity_window: 1e9}"}) {
    try {
      LegPipelineOptions::fromYaml(YAML::Load(bad));
      ADD_FAILURE() << bad << " accepted";
    } catch (const std::runtime_error& e) {
      const std::string key = std::string(bad).substr(1, std::string(bad).find(':') - 1);
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  }
}

// Negative information: a laser that sees through a node's place and finds nobody lowers that node's
// likelihood by the detection probability at its range; out of view, occluded or near a person it does not.
TEST(LegPipeline, NegativeObservationListsEveryNodeAndLowersOnlyTheSeenEmptyOnes) {
  topology::PolytunnelSpec spec;
  spec.lanes = 4;
  spec.nodes_per_lane = 10;  // lane k at x = 1.5 k, nodes every 3 m along +y from y = 0
  const topology::TopologicalMap map = topology::makePolytunnelMap(spec);
  LegPipelineOptions o;  // defaults: p_detect 0.5 within 3 m, 0 from 5 m, period 2 s, clearance 1.5 m
  auto classifier = std::make_shared<LegClassifier>();
  classifier->load(std::string(PL_PACKAGE_DIR) + "/config/leg_classifier.yml");
  LegPipeline pipeline(classifier, o);
  // A laser at (0.75, 10.5) between lanes 0 and 1, looking along +y, 270 deg, every beam +inf (no return).
  const Eigen::Isometry3d laser =
      Eigen::Translation3d(0.75, 10.5, 0.0) * Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ());
  core::LaserScan scan;
  scan.angle_min = -2.356194;
  scan.angle_max = 2.356194;
  scan.angle_increment = 0.00872665;
  scan.range_min = 0.1;
  scan.range_max = 30.0;
  scan.ranges.assign(541, std::numeric_limits<float>::infinity());
  auto at = [&](const core::Observation& obs, const char* name) {
    const topology::NodeIndex n = *map.index(name);
    return obs.likelihood[n];
  };
  const auto obs = pipeline.negativeObservation("laser", 100.0, scan, laser, {}, map, "robot_1");
  ASSERT_TRUE(obs.has_value());
  EXPECT_FALSE(obs->identifying);
  EXPECT_EQ(obs->sensor, "lidar");
  EXPECT_EQ(obs->robot_id, "robot_1");
  EXPECT_FALSE(obs->position.has_value());
  ASSERT_EQ(obs->nodes.size(), map.numNodes());  // every node listed: the rest keeps likelihood 1
  EXPECT_EQ(core::validateObservation(*obs, map), "");
  EXPECT_DOUBLE_EQ(at(*obs, "r1_4"), 0.5);  // 1.7 m ahead
  EXPECT_DOUBLE_EQ(at(*obs, "r0_4"), 0.5);  // 1.7 m, the other lane
  EXPECT_DOUBLE_EQ(at(*obs, "r2_4"), 0.5);  // 2.7 m
  EXPECT_NEAR(at(*obs, "r1_5"), 1.0 - 0.5 * (5.0 - std::hypot(0.75, 4.5)) / 2.0, 1e-9);  // 4.6 m: tapered
  EXPECT_DOUBLE_EQ(at(*obs, "r1_3"), 1.0);  // 1.7 m behind: outside the 270 deg field of view
  EXPECT_DOUBLE_EQ(at(*obs, "r1_9"), 1.0);  // 16.5 m: beyond negative_range_max
  // At most one per period and frame; another frame has its own period.
  EXPECT_FALSE(pipeline.negativeObservation("laser", 101.0, scan, laser, {}, map, "robot_1").has_value());
  EXPECT_TRUE(pipeline.negativeObservation("laser_rear", 101.0, scan, laser, {}, map, "robot_1").has_value());
  EXPECT_TRUE(pipeline.negativeObservation("laser", 102.0, scan, laser, {}, map, "robot_1").has_value());

  // Someone the classifier did not report stands in r1_4's cell at (1.8, 12.5), 0.6 m from the node and off
  // the line of sight to it (beams -27.7 deg +- 3 deg return at 2.26 m): the laser cannot see through the
  // whole cell, which keeps likelihood 1; the other lane's r0_4 is still seen empty.
  core::LaserScan blocked = scan;
  for (std::size_t i = 0; i < blocked.ranges.size(); ++i)
    if (std::abs(blocked.angle(i) - std::atan2(-1.05, 2.0)) < 0.05) blocked.ranges[i] = 2.26f;
  LegPipeline undetected(classifier, o);
  const auto person_there =
      undetected.negativeObservation("laser", 100.0, blocked, laser, {}, map, "robot_1");
  ASSERT_TRUE(person_there.has_value());
  EXPECT_DOUBLE_EQ(at(*person_there, "r1_4"), 1.0);
  EXPECT_DOUBLE_EQ(at(*person_there, "r0_4"), 0.5);

  // A person candidate next to r0_4: that node keeps likelihood 1, r1_4 (1.8 m away) does not.
  LegPipeline with_person(classifier, o);
  const std::vector<PersonCandidate> person = {{Eigen::Vector2d(-0.3, 12.0), 0.9, "lidar", true}};
  const auto near = with_person.negativeObservation("laser", 100.0, scan, laser, person, map, "robot_1");
  ASSERT_TRUE(near.has_value());
  EXPECT_DOUBLE_EQ(at(*near, "r0_4"), 1.0);
  EXPECT_DOUBLE_EQ(at(*near, "r1_4"), 0.5);

  // Something 1 m in front of every beam: the laser sees no node's place, so it says nothing.
  LegPipeline occluded(classifier, o);
  core::LaserScan wall = scan;
  wall.ranges.assign(541, 1.0f);
  EXPECT_FALSE(occluded.negativeObservation("laser", 100.0, wall, laser, {}, map, "robot_1").has_value());
  // Beams that return nothing valid (NaN) see nothing either.
  wall.ranges.assign(541, std::numeric_limits<float>::quiet_NaN());
  EXPECT_FALSE(occluded.negativeObservation("laser", 100.0, wall, laser, {}, map, "robot_1").has_value());

  // Switched off.
  o.negative_information = false;
  LegPipeline off(classifier, o);
  EXPECT_FALSE(off.negativeObservation("laser", 100.0, scan, laser, {}, map, "robot_1").has_value());
}

// Images smaller than the HOG window (64 x 128) or of another type crashed OpenCV 4.6 once: no boxes now.
TEST(HogPersonDetector, TinyAndOddImagesGiveNoBoxesAndNoCrash) {
  picker_localisation::vision::HogPersonDetector hog;
  for (const cv::Size s : {cv::Size(1, 1), cv::Size(10, 10), cv::Size(128, 64), cv::Size(640, 2), cv::Size(63, 127),
                           cv::Size(2, 640)})
    EXPECT_TRUE(hog.detect(cv::Mat(s, CV_8UC3, cv::Scalar::all(128))).empty()) << s;
  EXPECT_TRUE(hog.detect(cv::Mat(200, 100, CV_8UC1, cv::Scalar::all(128))).empty());
  EXPECT_TRUE(hog.detect(cv::Mat(200, 100, CV_32FC3, cv::Scalar::all(0.5))).empty());
  // A frame of the window size is processed (whatever it finds).
  EXPECT_NO_THROW(hog.detect(cv::Mat(128, 64, CV_8UC3, cv::Scalar::all(128))));
}

// The ONNX path through cv::dnn, with models generated at build time by test/make_test_onnx.py
// (python3-onnx): person_ssd.onnx outputs a person row whose score is the mean of the input blob, box (0.1,
// 0.2)-(0.4, 0.9) of the image, and a row of another class; wrong_shape.onnx outputs [1 x 1 x 1 x 5].
TEST(OnnxPersonDetector, GeneratedModelGivesItsBoxAndAWrongShapeIsRefused) {
  OnnxOptions o;
  o.model_path = std::string(PL_TEST_ONNX_DIR) + "/person_ssd.onnx";
  const OnnxPersonDetector onnx(o);  // 300 x 300 input, blob = (pixel - 127.5) / 127.5, person class 1
  const cv::Mat bright(480, 640, CV_8UC3, cv::Scalar::all(230));
  const std::vector<PersonBox> boxes = onnx.detect(bright);
  ASSERT_EQ(boxes.size(), 1u);  // the class-2 row (score 0.99) is not a person
  EXPECT_EQ(boxes[0].box,
            cv::Rect(cv::Point(64, 96), cv::Point(256, 432)));  // 0.1..0.4 x 640, 0.2..0.9 x 480
  // cv::dnn's ReduceMean gives 0.8015 for the exact 0.8039; a wrong mean, scale or channel order would be far
  // off.
  EXPECT_NEAR(boxes[0].confidence, (230.0 - 127.5) / 127.5, 0.01);
  // A dark image: blob mean (40 - 127.5) / 127.5 < 0: below min_confidence 0.5, nothing.
  EXPECT_TRUE(onnx.detect(cv::Mat(480, 640, CV_8UC3, cv::Scalar::all(40))).empty());
  o.min_confidence = 0.9;  // 0.80 is not enough
  EXPECT_TRUE(OnnxPersonDetector(o).detect(bright).empty());

  auto refusal = [](const OnnxOptions& options) {
    try {
      OnnxPersonDetector d(options);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  OnnxOptions wrong;
  wrong.model_path = std::string(PL_TEST_ONNX_DIR) + "/wrong_shape.onnx";
  EXPECT_NE(refusal(wrong).find("outputs [1 x 1 x 1 x 5], expected rows of 7"), std::string::npos)
      << refusal(wrong);
  OnnxOptions missing;
  missing.model_path = std::string(PL_TEST_ONNX_DIR) + "/no_such_model.onnx";
  EXPECT_NE(refusal(missing).find("cannot read"), std::string::npos) << refusal(missing);
}

TEST(LegDetectorThreshold, ScaledDownForCoarserLasersOnly) {
  LegDetectorOptions o;  // 0.6 at 0.006136 rad
  EXPECT_DOUBLE_EQ(thresholdFor(o, 0.006136), 0.6);
  EXPECT_DOUBLE_EQ(thresholdFor(o, 0.004363), 0.6);            // a finer laser keeps the threshold
  EXPECT_NEAR(thresholdFor(o, 2 * 0.006136), 0.3, 1e-12);      // twice the spacing: half the threshold
  EXPECT_NEAR(thresholdFor(o, -2 * 0.006136), 0.3, 1e-12);     // a scan turning clockwise
  EXPECT_NEAR(thresholdFor(o, 0.00872665), 0.6 * 0.006136 / 0.00872665, 1e-12);
  o.threshold_reference_increment = 0.0;
  EXPECT_DOUBLE_EQ(thresholdFor(o, 0.1), 0.6);                  // scaling off
  EXPECT_DOUBLE_EQ(thresholdFor(LegDetectorOptions{}, 0.0), 0.6);  // no increment given
}

TEST(Segmentation, DecimatedScanKeepsEveryKthBeam) {
  core::LaserScan s;
  s.angle_min = -1.0;
  s.angle_increment = 0.01;
  s.range_max = 10.0;
  for (int i = 0; i < 7; ++i) s.ranges.push_back(1.0f + i);
  const auto d = decimateScan(s, 3);
  ASSERT_EQ(d.ranges.size(), 3u);  // beams 0, 3, 6
  EXPECT_FLOAT_EQ(d.ranges[1], 4.0f);
  EXPECT_DOUBLE_EQ(d.angle_increment, 0.03);
  EXPECT_DOUBLE_EQ(d.angle(2), s.angle(6));
  EXPECT_EQ(decimateScan(s, 1).ranges.size(), 7u);
}
