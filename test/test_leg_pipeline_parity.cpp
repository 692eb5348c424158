// rostest: the leg_detector node and the offline runner's pipeline (vision::LegPipeline built as
// eval::runOnce builds it) turn identical scans into identical Observations. Real labelled scans (leg_tracker
// positive_4) are published on two laser topics in two frames, interleaved as two corner lasers would be, so
// a runner that shared one tracker between the lasers (a bug it once had) produces other observations. The
// lasers' negative information ("nobody at these nodes") is compared too.
#include <geometry_msgs/PoseArray.h>
#include <gtest/gtest.h>
#include <picker_localisation/Observation.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include <algorithm>
#include <cmath>

#include "picker_localisation/eval/experiment.h"
#include "picker_localisation/ros/vision_io.h"
#include "picker_localisation/sensors_vision/leg_pipeline.h"
#include "picker_localisation/topology/map_io.h"
#include "vision_rostest_util.h"

using vision_test::waitFor;
namespace pl = picker_localisation;

namespace {
struct Laser {
  const char* topic;
  const char* frame;
  double x, y, yaw;
};
// Two corner lasers facing opposite ways, near the first lane of the map.
const Laser kLasers[2] = {{"robot_1/scan_front", "robot_1/laser_front", 14.0, -20.0, 0.0},
                          {"robot_1/scan_rear", "robot_1/laser_rear", 14.4, -20.3, M_PI}};

Eigen::Isometry3d poseOf(const Laser& l) {
  return Eigen::Translation3d(l.x, l.y, 0.0) * Eigen::AngleAxisd(l.yaw, Eigen::Vector3d::UnitZ());
}
}  // namespace

TEST(LegPipelineParity, NodeEqualsRunnerPipeline) {
  ros::NodeHandle nh;
  std::vector<pl::Observation> received;
  auto sub = nh.subscribe<pl::Observation>(
      "/person_observations", 1000, [&](const pl::Observation::ConstPtr& m) { received.push_back(*m); });
  ros::Publisher pubs[2] = {nh.advertise<sensor_msgs::LaserScan>(kLasers[0].topic, 100),
                            nh.advertise<sensor_msgs::LaserScan>(kLasers[1].topic, 100)};
  tf2_ros::StaticTransformBroadcaster tfb;
  std::vector<geometry_msgs::TransformStamped> tfs;
  for (const auto& l : kLasers) {
    geometry_msgs::TransformStamped t;
    t.header.stamp = ros::Time(0.001);
    t.header.frame_id = "map";
    t.child_frame_id = l.frame;
    t.transform.translation.x = l.x;
    t.transform.translation.y = l.y;
    t.transform.rotation.z = std::sin(0.5 * l.yaw);
    t.transform.rotation.w = std::cos(0.5 * l.yaw);
    tfs.push_back(t);
  }
  tfb.sendTransform(tfs);
  ASSERT_TRUE(waitFor(
      [&] {
        return pubs[0].getNumSubscribers() > 0 && pubs[1].getNumSubscribers() > 0 &&
               sub.getNumPublishers() > 0;
      },
      30.0));
  waitFor([] { return false; }, 1.0);  // let the node's tf listener receive the static transforms

  rosbag::Bag bag(std::string(PL_TEST_DATA) + "/leg_tracker/positive_4_extracted.bag");
  rosbag::View view(bag, rosbag::TopicQuery(std::vector<std::string>{"/training_scan"}));
  std::vector<sensor_msgs::LaserScan> scans;
  for (const auto& m : view)
    if (auto s = m.instantiate<sensor_msgs::LaserScan>()) scans.push_back(*s);
  ASSERT_GE(scans.size(), 60u);

  // The runner's pipeline, built exactly as eval::runOnce builds it.
  auto classifier = std::make_shared<pl::vision::LegClassifier>();
  classifier->load(std::string(PL_PACKAGE_DIR) + "/config/leg_classifier.yml");
  pl::vision::LegPipeline runner(
      classifier, pl::vision::LegPipelineOptions::fromYamlFiles(pl::eval::visionConfigFiles("")));
  const auto map = pl::topology::loadMap(std::string(PL_PACKAGE_DIR) + "/config/maps/riseholme.tmap2");

  // Scan k goes to laser k % 2 (both lasers see the same real scan content, as two lasers of one robot would
  // see people at other places): each laser's tracker must see only its own scans.
  std::vector<pl::core::Observation> expected;
  std::size_t negatives = 0;
  const double t0 = 100.0;
  for (std::size_t k = 0; k < 60; ++k) {
    const Laser& l = kLasers[k % 2];
    sensor_msgs::LaserScan s = scans[k / 2];
    s.header.stamp = ros::Time(t0 + 0.05 * static_cast<double>(k));
    s.header.frame_id = l.frame;
    // Four open-field scans (every beam +inf, REP 117), two per laser 2.1 s apart: each laser sees through
    // some nodes' cells and sends negative information (the room of the real scans hides every node).
    if (k == 4 || k == 5 || k == 46 || k == 47) std::fill(s.ranges.begin(), s.ranges.end(), INFINITY);
    const pl::core::LaserScan scan = pl::ros_adapter::toScanData(s);
    const auto candidates = runner.scanCandidates(scan, poseOf(l));
    for (const auto& p : runner.track(l.frame, s.header.stamp.toSec(), candidates))
      expected.push_back(pl::vision::LegPipeline::observation(p, map, s.header.stamp.toSec(), "robot_1"));
    // The negative information of the scan ("nobody at these nodes"), after its people, as the node sends it.
    if (auto negative = runner.negativeObservation(l.frame, s.header.stamp.toSec(), scan, poseOf(l),
                                                   candidates, map, "robot_1")) {
      expected.push_back(*negative);
      ++negatives;
    }
    pubs[k % 2].publish(s);
    // The next scan (the other laser's topic) only once this one's observations came: a loaded node could
    // otherwise take the two topics in another order and interleave the lasers' observations differently.
    ASSERT_TRUE(waitFor([&] { return received.size() >= expected.size(); }))
        << received.size() << " of " << expected.size() << " observations after scan " << k;
    waitFor([] { return false; }, 0.05);
  }
  ASSERT_GT(expected.size(), 10u) << "too few people in the scans to compare";
  ASSERT_EQ(negatives, 4u) << "each laser's two open-field scans, 2.1 s apart, give negative information";
  ASSERT_TRUE(waitFor([&] { return received.size() >= expected.size(); }))
      << received.size() << " of " << expected.size() << " observations";
  waitFor([] { return false; }, 0.5);
  ASSERT_EQ(received.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const auto& a = received[i];
    const auto& e = expected[i];
    EXPECT_NEAR(a.header.stamp.toSec(), e.stamp, 1e-6) << i;
    EXPECT_EQ(a.sensor, e.sensor);
    EXPECT_FALSE(a.identifying);
    if (e.position) {
      EXPECT_NEAR(a.position.x, e.position->x(), 1e-9) << i;
      EXPECT_NEAR(a.position.y, e.position->y(), 1e-9) << i;
      EXPECT_NEAR(a.position_covariance[0], e.position_covariance(0, 0), 1e-12) << i;
    } else {
      EXPECT_TRUE(std::isnan(a.position.x)) << i << ": a negative observation has no position";
    }
    ASSERT_EQ(a.nodes.size(), e.nodes.size()) << i;
    for (std::size_t j = 0; j < e.nodes.size(); ++j) {
      EXPECT_EQ(a.nodes[j], map.node(e.nodes[j]).name) << i;
      EXPECT_NEAR(a.likelihood[j], e.likelihood[j], 1e-12) << i;
    }
  }

  // The bug this guards against: one tracker shared by both lasers confirms other people.
  pl::vision::LegPipeline shared(
      classifier, pl::vision::LegPipelineOptions::fromYamlFiles(pl::eval::visionConfigFiles("")));
  std::size_t shared_count = 0;
  for (std::size_t k = 0; k < 60; ++k) {
    sensor_msgs::LaserScan s = scans[k / 2];
    if (k == 4 || k == 5 || k == 46 || k == 47) std::fill(s.ranges.begin(), s.ranges.end(), INFINITY);
    shared_count += shared
                        .processScan("one_frame", t0 + 0.05 * static_cast<double>(k),
                                     pl::ros_adapter::toScanData(s), poseOf(kLasers[k % 2]))
                        .size();
  }
  EXPECT_LT(shared_count, expected.size() - negatives) << "a shared tracker should confirm fewer people";
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_leg_pipeline_parity");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
