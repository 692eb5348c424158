// rostest of leg_detector: real scans of the held-out labelled bag (leg_tracker positive_4) are published with a
// static map -> right_laser transform; the node must publish people near the labelled legs (in the map frame)
// and non-identifying lidar Observations; an empty scan and a scan in a frame without tf must not kill it.
#include <gtest/gtest.h>
#include <picker_localisation/BearingDetectionArray.h>
#include <picker_localisation/Observation.h>
#include <picker_localisation/PersonDetectionArray.h>
#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>

#include <geometry_msgs/PoseArray.h>
#include <diagnostic_msgs/DiagnosticArray.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include "picker_localisation/ros/leg_detector_node.h"
#include "vision_rostest_util.h"

using vision_test::waitFor;

namespace {

constexpr double kOffsetX = 14.0, kOffsetY = -20.0;  // map -> right_laser translation (near the first node)

struct Recorder {
  std::vector<picker_localisation::PersonDetectionArray> people;
  std::vector<picker_localisation::Observation> observations;
  void onPeople(const picker_localisation::PersonDetectionArray::ConstPtr& m) { people.push_back(*m); }
  void onObservation(const picker_localisation::Observation::ConstPtr& m) { observations.push_back(*m); }
};

// The leg detector's diagnostics values, kept up to date in `diag` while the subscriber lives.
ros::Subscriber followDiagnostics(ros::NodeHandle& nh, std::map<std::string, std::string>& diag) {
  return nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 20, [&diag](const diagnostic_msgs::DiagnosticArray::ConstPtr& m) {
        for (const auto& st : m->status)
          if (st.name.find("leg detector") != std::string::npos)
            for (const auto& kv : st.values) diag[kv.key] = kv.value;
      });
}

}  // namespace

TEST(LegDetectorNode, RealScansEmptyScanAndMissingTf) {
  ros::NodeHandle nh;
  Recorder rec;
  auto people_sub = nh.subscribe("people", 100, &Recorder::onPeople, &rec);
  auto obs_sub = nh.subscribe("/observations", 100, &Recorder::onObservation, &rec);
  auto pub = nh.advertise<sensor_msgs::LaserScan>("scan_front", 100);
  tf2_ros::StaticTransformBroadcaster tfb;
  geometry_msgs::TransformStamped t;
  t.header.stamp = ros::Time::now();
  t.header.frame_id = "map";
  t.child_frame_id = "right_laser";
  t.transform.translation.x = kOffsetX;
  t.transform.translation.y = kOffsetY;
  t.transform.rotation.w = 1.0;
  tfb.sendTransform(t);
  ASSERT_TRUE(waitFor([&] { return pub.getNumSubscribers() > 0 && people_sub.getNumPublishers() > 0; }, 30.0));

  // The first 40 labelled scans, in order, at 10 Hz with fresh stamps.
  rosbag::Bag bag(std::string(PL_TEST_DATA) + "/leg_tracker/positive_4_extracted.bag");
  rosbag::View view(bag, rosbag::TopicQuery(std::vector<std::string>{"/training_scan", "/leg_cluster_positions"}));
  std::vector<sensor_msgs::LaserScan> scans;
  std::vector<std::vector<std::pair<double, double>>> labels;
  for (const auto& m : view) {
    if (auto s = m.instantiate<sensor_msgs::LaserScan>()) scans.push_back(*s);
    if (auto p = m.instantiate<geometry_msgs::PoseArray>()) {
      labels.emplace_back();
      for (const auto& pose : p->poses) labels.back().emplace_back(pose.position.x, pose.position.y);
    }
  }
  ASSERT_GE(scans.size(), 40u);
  ros::Time last_stamp;
  for (std::size_t i = 0; i < 40; ++i) {
    auto s = scans[i];
    s.header.stamp = last_stamp = ros::Time::now();
    s.header.frame_id = "right_laser";
    pub.publish(s);
    waitFor([] { return false; }, 0.1);
  }
  ASSERT_TRUE(waitFor([&] { return rec.people.size() >= 40; })) << rec.people.size() << " people messages";

  // People: map frame, robot id, near a labelled leg of the scan (+ the tf offset), tracked.
  std::size_t near = 0, total = 0;
  for (std::size_t i = 0; i < rec.people.size() && i < 40; ++i) {
    const auto& a = rec.people[i];
    EXPECT_EQ(a.header.frame_id, "map");
    EXPECT_EQ(a.robot_id, "robot_1");
    for (const auto& d : a.detections) {
      ++total;
      EXPECT_GE(d.track_id, 0);
      EXPECT_GT(d.confidence, 0.0);
      EXPECT_LE(d.confidence, 1.0);
      EXPECT_EQ(d.sensor, "lidar");
      double best = std::numeric_limits<double>::infinity();
      for (const auto& l : labels[i])
        best = std::min(best, std::hypot(d.position.x - (l.first + kOffsetX), d.position.y - (l.second + kOffsetY)));
      near += best < 0.5 ? 1 : 0;
    }
  }
  EXPECT_GT(near, 5u) << "people near the labelled legs: " << near << " of " << total;
  // Observations: one per published person, non-identifying lidar likelihoods over map nodes.
  ASSERT_TRUE(waitFor([&] { return rec.observations.size() >= total; }));
  EXPECT_EQ(rec.observations.size(), total);
  for (const auto& o : rec.observations) {
    EXPECT_EQ(o.sensor, "lidar");
    EXPECT_FALSE(o.identifying);
    EXPECT_TRUE(o.picker_id.empty());
    EXPECT_EQ(o.robot_id, "robot_1");
    EXPECT_EQ(o.header.frame_id, "map");
    ASSERT_FALSE(o.nodes.empty());
    EXPECT_EQ(o.nodes.size(), o.likelihood.size());
    EXPECT_TRUE(std::isfinite(o.position.x));
  }

  // A scan with no return at all (+inf: free space) and a scan in a frame without tf: no people, no crash.
  const std::size_t before = rec.people.size();
  // Scan `i` of the bag, restamped, in `frame`, changed by `edit`.
  auto sendScan = [&](std::size_t i, const std::string& frame, const ros::Time& stamp,
                      const std::function<void(sensor_msgs::LaserScan&)>& edit = {}) {
    auto s = scans[i];
    s.header.stamp = stamp;
    s.header.frame_id = frame;
    if (edit) edit(s);
    pub.publish(s);
    waitFor([] { return false; }, 0.2);
  };
  sendScan(0, "right_laser", ros::Time::now(), [](sensor_msgs::LaserScan& s) {
    std::fill(s.ranges.begin(), s.ranges.end(), std::numeric_limits<float>::infinity());
  });
  sendScan(1, "no_such_laser", ros::Time::now());
  // Malformed scans: a scan stamped 2100, one without a frame id (tf2 printed ~170 lines), one of 1,000,000
  // beams (blocked the node for 10 s), camera detections with an Inf bearing and in a frame without tf.
  sendScan(2, "right_laser", ros::Time(4102444800.0));
  sendScan(3, "", ros::Time::now());
  sendScan(4, "right_laser", ros::Time::now(), [](sensor_msgs::LaserScan& s) { s.ranges.assign(1000000, 3.0f); });
  // The free-space scan's people message and negative observation (however slow the machine), then nothing
  // more from the other four.
  ASSERT_TRUE(waitFor([&] {
    return rec.people.size() > before && std::any_of(rec.observations.begin(), rec.observations.end(),
                                                     [](const auto& o) { return std::isnan(o.position.x); });
  }));
  waitFor([] { return false; }, 0.8);
  ASSERT_EQ(rec.people.size(), before + 1);  // the free-space scan is processed: one message, nobody in it
  EXPECT_TRUE(rec.people.back().detections.empty());
  // The scan of +inf beams saw free space (REP 117): no person, but one negative observation ("nobody at
  // these nodes"): anonymous, no position, every map node listed, some of them below 1. The real scans before
  // it (a room: walls hide every node's place) gave none.
  std::size_t negatives = 0;
  for (const auto& o : rec.observations) {
    if (!std::isnan(o.position.x)) continue;
    ++negatives;
    EXPECT_FALSE(o.identifying);
    EXPECT_EQ(o.nodes.size(), 138u);
    ASSERT_EQ(o.likelihood.size(), o.nodes.size());
    EXPECT_LT(*std::min_element(o.likelihood.begin(), o.likelihood.end()), 1.0);
    EXPECT_DOUBLE_EQ(*std::max_element(o.likelihood.begin(), o.likelihood.end()), 1.0);
  }
  EXPECT_EQ(negatives, 1u);
  std::map<std::string, std::string> diag;
  auto diag_sub = followDiagnostics(nh, diag);
  ASSERT_TRUE(waitFor([&] { return diag["scans over max_beams (dropped)"] == "1"; }))
      << diag["scans over max_beams (dropped)"];
  EXPECT_EQ(diag["stamps in the future (dropped)"], "1");
  EXPECT_EQ(diag["tf failures (dropped)"], "2");  // no_such_laser and the scan without a frame id
  // Still alive: a good scan produces output again.
  sendScan(40, "right_laser", ros::Time::now());
  EXPECT_TRUE(waitFor([&] { return rec.people.size() > before; })) << "leg_detector stopped publishing";
  {
    auto cam_bad = nh.advertise<picker_localisation::BearingDetectionArray>("camera/detections", 10);
    ASSERT_TRUE(waitFor([&] { return cam_bad.getNumSubscribers() > 0; }));
    picker_localisation::BearingDetectionArray cam;
    cam.header.stamp = ros::Time::now();
    cam.header.frame_id = "right_laser";
    cam.detections.resize(1);
    cam.detections[0].bearing = std::numeric_limits<double>::infinity();
    cam.detections[0].confidence = 0.9;
    cam_bad.publish(cam);  // Inf bearing: dropped
    waitFor([] { return false; }, 0.2);
    cam.header.frame_id = "no_such_camera";
    cam.detections[0].bearing = 0.1;
    cam_bad.publish(cam);  // fused with the next scan: no tf, the scan is still published unfused
    waitFor([] { return false; }, 0.2);
    const std::size_t at = rec.people.size();
    sendScan(41, "right_laser", cam.header.stamp);
    EXPECT_TRUE(waitFor([&] { return rec.people.size() > at; })) << "no people after bad camera detections";
    // A status taken after scan 41 (one taken between the camera detections and it counts 2 tf failures).
    ASSERT_TRUE(waitFor([&] {
      return diag["non-finite camera detections (dropped)"] == "1" && diag["tf failures (dropped)"] == "3";
    })) << diag["non-finite camera detections (dropped)"];
    EXPECT_EQ(diag["tf failures (dropped)"], "3");  // + the camera frame without tf
  }

  // Fusion (Algorithm 4): a camera bearing towards the labelled legs, stamped like the scan, promotes the nearest
  // cluster in the cone to a camera-confirmed person ("lidar_camera", confidence >= 0.6) at the legs.
  auto cam_pub = nh.advertise<picker_localisation::BearingDetectionArray>("camera/detections", 10);
  ASSERT_TRUE(waitFor([&] { return cam_pub.getNumSubscribers() > 0; }));
  const std::size_t fusion_start = rec.people.size();
  std::vector<std::size_t> fused_scan;
  for (std::size_t i = 41; i < 61 && i < scans.size(); ++i) {
    double mx = 0, my = 0;
    for (const auto& l : labels[i]) {
      mx += l.first / labels[i].size();
      my += l.second / labels[i].size();
    }
    const ros::Time stamp = ros::Time::now();
    picker_localisation::BearingDetectionArray cam;
    cam.header.stamp = stamp;
    cam.header.frame_id = "right_laser";
    picker_localisation::BearingDetection b;
    b.bearing = std::atan2(my, mx);
    b.confidence = 0.9;
    cam.detections.push_back(b);
    cam_pub.publish(cam);
    waitFor([] { return false; }, 0.05);
    auto s = scans[i];
    s.header.stamp = stamp;
    s.header.frame_id = "right_laser";
    pub.publish(s);
    fused_scan.push_back(i);
    waitFor([] { return false; }, 0.1);
  }
  ASSERT_TRUE(waitFor([&] { return rec.people.size() >= fusion_start + fused_scan.size(); }));
  std::size_t camera_near = 0;
  for (std::size_t k = 0; k < fused_scan.size(); ++k)
    for (const auto& d : rec.people[fusion_start + k].detections) {
      if (d.sensor != "lidar_camera") continue;
      EXPECT_GE(d.confidence, 0.6);
      for (const auto& l : labels[fused_scan[k]])
        if (std::hypot(d.position.x - (l.first + kOffsetX), d.position.y - (l.second + kOffsetY)) < 0.5) {
          ++camera_near;
          break;
        }
    }
  EXPECT_GE(camera_near, fused_scan.size() / 2) << "camera-confirmed people at the labelled legs";
}

// 3D LiDAR input: a synthetic cloud in the laser frame (ground at z = 0, a 0.3 x 0.4 x 1.7 m person at
// (3, 1), a low bush) gives a "lidar3d" person at the person's position in the map frame once tracked.
TEST(LegDetectorNode, PointCloudPerson) {
  ros::NodeHandle nh;
  Recorder rec;
  auto people_sub = nh.subscribe("people", 100, &Recorder::onPeople, &rec);
  auto pub = nh.advertise<sensor_msgs::PointCloud2>("points", 10);
  ASSERT_TRUE(waitFor([&] { return pub.getNumSubscribers() > 0 && people_sub.getNumPublishers() > 0; }, 30.0));
  std::vector<Eigen::Vector3f> pts;
  auto box = [&](Eigen::Vector3f lo, Eigen::Vector3f hi, float step) {
    for (float x = lo.x(); x <= hi.x() + 1e-6f; x += step)
      for (float y = lo.y(); y <= hi.y() + 1e-6f; y += step)
        for (float z = lo.z(); z <= hi.z() + 1e-6f; z += step) pts.emplace_back(x, y, z);
  };
  box({-1, -3, 0}, {6, 4, 0}, 0.1f);
  box({3.0f, 1.0f, 0.05f}, {3.3f, 1.4f, 1.75f}, 0.05f);
  box({1.0f, -2.0f, 0.05f}, {1.5f, -1.5f, 0.5f}, 0.05f);
  sensor_msgs::PointCloud2 cloud;
  cloud.header.frame_id = "right_laser";
  sensor_msgs::PointCloud2Modifier mod(cloud);
  mod.setPointCloud2FieldsByString(1, "xyz");
  mod.resize(pts.size());
  sensor_msgs::PointCloud2Iterator<float> x(cloud, "x"), y(cloud, "y"), z(cloud, "z");
  for (const auto& p : pts) {
    *x = p.x();
    *y = p.y();
    *z = p.z();
    ++x, ++y, ++z;
  }
  // Malformed clouds first (they once crashed the node: SIGSEGV on width x point_step beyond the data):
  // dropped, node alive.
  {
    sensor_msgs::PointCloud2 bad = cloud;
    bad.header.stamp = ros::Time::now();
    bad.width = 100000000;
    bad.row_step = bad.width * bad.point_step;
    bad.data.resize(12);
    pub.publish(bad);
    waitFor([] { return false; }, 0.3);  // the node queues 2 clouds
    bad = cloud;
    bad.header.stamp = ros::Time::now();
    bad.point_step = 0;
    pub.publish(bad);
    waitFor([] { return false; }, 0.3);  // the node queues 2 clouds
    bad = cloud;
    bad.header.stamp = ros::Time::now();
    for (auto& f : bad.fields) f.datatype = sensor_msgs::PointField::FLOAT64;
    pub.publish(bad);
    waitFor([] { return false; }, 0.3);  // the node queues 2 clouds
    bad = cloud;
    bad.header.stamp = ros::Time(4102444800.0);  // 2100: ros::Duration threw in the tf lookup
    pub.publish(bad);
    waitFor([] { return false; }, 0.3);  // the node queues 2 clouds
    // Well-formed metadata, hostile content: all NaN, and one point at z = 1e38 (its voxel sums overflowed
    // into Inf and PCL's k-d tree aborted the process); a frame without tf; no frame id.
    bad = cloud;
    bad.header.stamp = ros::Time::now();
    for (sensor_msgs::PointCloud2Iterator<float> bx(bad, "x"); bx != bx.end(); ++bx) bx[0] = bx[1] = bx[2] = NAN;
    pub.publish(bad);
    waitFor([] { return false; }, 0.3);
    bad = cloud;
    bad.header.stamp = ros::Time::now();
    sensor_msgs::PointCloud2Iterator<float>(bad, "z")[0] = 1e38f;
    pub.publish(bad);
    waitFor([] { return false; }, 0.3);
    bad = cloud;
    bad.header.stamp = ros::Time::now();
    bad.header.frame_id = "no_such_lidar";
    pub.publish(bad);
    waitFor([] { return false; }, 0.3);
    bad.header.frame_id = "";
    pub.publish(bad);
    waitFor([] { return false; }, 0.5);
    std::size_t detections = 0;
    for (const auto& a : rec.people)
      detections += a.detections.size();  // a single good-shaped cloud is not yet a confirmed track either
    EXPECT_EQ(detections, 0u) << "people from a malformed or unlocated cloud";
    EXPECT_EQ(picker_localisation::ros_adapter::cloudProblem(cloud), "");
    // Counted in diagnostics (published at 1 Hz).
    std::map<std::string, std::string> diag;
    auto diag_sub = followDiagnostics(nh, diag);
    // A status taken after the cloud stamped 2100 too (the fourth, after the three malformed ones).
    ASSERT_TRUE(waitFor([&] {
      return diag["malformed clouds (dropped)"] == "3" && diag["stamps in the future (dropped)"] == "2";
    })) << diag["malformed clouds (dropped)"];
    EXPECT_EQ(diag["stamps in the future (dropped)"], "2");  // + the scan of RealScansEmptyScanAndMissingTf (one node)
  }
  const std::size_t start = rec.people.size();
  for (std::size_t k = 0; k < 5; ++k) {
    cloud.header.stamp = ros::Time::now();
    pub.publish(cloud);
    // One people message per cloud: the next cloud after it (the node queues 2 clouds: a slow node drops).
    ASSERT_TRUE(waitFor([&] { return rec.people.size() > start + k; })) << "cloud " << k << " not processed";
    waitFor([] { return false; }, 0.2);
  }
  ASSERT_TRUE(waitFor([&] { return rec.people.size() >= 5; }));
  bool found = false;
  for (const auto& a : rec.people)
    for (const auto& d : a.detections) {
      if (d.sensor != "lidar3d") continue;
      EXPECT_NEAR(d.position.x, 3.15 + kOffsetX, 0.1);
      EXPECT_NEAR(d.position.y, 1.2 + kOffsetY, 0.1);
      found = true;
    }
  EXPECT_TRUE(found);
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_leg_detector_node");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
