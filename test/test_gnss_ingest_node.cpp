// rostest: gnss_ingest through ROS. Bad fixes (NaN, NO_FIX, negative covariance, repeated and backwards
// stamps) publish nothing and do not stop the node; good fixes before and after become identifying
// Observations at the right place; diagnostics count the rejections.
#include <geometry_msgs/PoseArray.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <gtest/gtest.h>
#include <sensor_msgs/NavSatFix.h>

#include <picker_localisation/GnssBias.h>
#include <picker_localisation/PickerList.h>

#include <cmath>

#include "picker_localisation/core/observation.h"
#include "picker_localisation/ros/observation_conversions.h"
#include "picker_localisation/core/geodetic_datum.h"
#include "picker_localisation/topology/map_io.h"
#include "ranging_rostest_util.h"

using picker_localisation::core::GeodeticDatum;

using ranging_test::fixAt;

namespace {
// The files the launch file gives the node.
GeodeticDatum shippedDatum() { return GeodeticDatum::load(std::string(PL_PACKAGE_DIR) + "/config/datum.yaml"); }
picker_localisation::topology::TopologicalMap shippedMap() {
  return picker_localisation::topology::loadMap(std::string(PL_PACKAGE_DIR) + "/config/maps/riseholme.tmap2");
}
// Where picker_3 stands, and how far off its unit reads (3.6 m): the people test teaches gnss_ingest this offset,
// and the PoseArray test relies on it.
const Eigen::Vector2d kPicker3Truth(15.0, -2.0), kPicker3Offset(3.0, 2.0);
// A LiDAR person of robot_1 at `at` (map frame), as leg_detector publishes it.
picker_localisation::Observation personAt(const picker_localisation::topology::TopologicalMap& map,
                                          const Eigen::Vector2d& at, const ros::Time& stamp) {
  picker_localisation::core::Observation o;
  o.stamp = stamp.toSec();
  o.sensor = "lidar";
  o.robot_id = "robot_1";
  o.position = at;
  o.position_covariance = Eigen::Matrix2d::Identity() * 0.09;
  picker_localisation::core::setGaussianLikelihood(o, map, at, o.position_covariance);
  return picker_localisation::ros_adapter::toMsg(o, map);
}
}  // namespace

TEST(GnssIngestNode, BadFixesAreRejectedAndGoodOnesStillPublish) {
  ros::NodeHandle nh;
  ranging_test::Collector c(nh, "GNSS ingestion");
  const GeodeticDatum datum = shippedDatum();
  ros::Publisher p1 = nh.advertise<sensor_msgs::NavSatFix>("/pickers/picker_1/fix", 20);
  ros::Publisher p2 = nh.advertise<sensor_msgs::NavSatFix>("/pickers/picker_2/fix", 20);
  ASSERT_TRUE(ranging_test::waitFor([&] {
    return p1.getNumSubscribers() > 0 && p2.getNumSubscribers() > 0 && c.obs_sub.getNumPublishers() > 0;
  }, 30.0));
  const Eigen::Vector2d where(20.0, -20.0);  // inside the Riseholme polytunnels
  const ros::Time t0 = ros::Time::now();
  auto send = [&](ros::Publisher& p, const sensor_msgs::NavSatFix& f) {
    p.publish(f);
    ranging_test::spinFor(0.05);
  };
  sensor_msgs::NavSatFix f = fixAt(datum, where, t0);
  f.latitude = std::nan("");
  send(p1, f);                                        // NaN
  f = fixAt(datum, where, t0);
  f.status.status = sensor_msgs::NavSatStatus::STATUS_NO_FIX;
  send(p1, f);                                        // NO_FIX
  f = fixAt(datum, where, t0);
  f.position_covariance[0] = -1.0;
  send(p1, f);                                        // negative covariance
  send(p1, fixAt(datum, where, t0));                  // good
  ASSERT_TRUE(ranging_test::waitFor([&] { return c.obs.size() >= 1; }));
  send(p1, fixAt(datum, where, t0));                                        // repeated stamp
  send(p1, fixAt(datum, where, t0 - ros::Duration(1.0)));                   // backwards
  send(p1, fixAt(datum, where, ros::Time(4102444800.0)));                   // 2100-01-01: far future, dropped
  for (int k = 1; k <= 5; ++k)  // five fixes 50 km away: off the map, neither snapped nor re-anchoring the gate
    send(p1, fixAt(datum, where + Eigen::Vector2d(50000.0, 0.0), t0 + ros::Duration(0.1 * k)));
  send(p1, fixAt(datum, where + Eigen::Vector2d(0.5, 0.0), t0 + ros::Duration(1.0)));  // good again
  send(p2, fixAt(datum, Eigen::Vector2d(25.0, -30.0), t0 + ros::Duration(1.0)));       // other picker
  ASSERT_TRUE(ranging_test::waitFor([&] { return c.obs.size() >= 3; }));
  ranging_test::spinFor(0.5);
  ASSERT_EQ(c.obs.size(), 3u);
  EXPECT_EQ(ranging_test::countFor(c.obs, "picker_1"), 2u);
  EXPECT_EQ(ranging_test::countFor(c.obs, "picker_2"), 1u);
  for (const auto& o : c.obs) {
    EXPECT_TRUE(o.identifying);
    EXPECT_EQ(o.sensor, "gnss");
    EXPECT_EQ(o.header.frame_id, "map");
    EXPECT_FALSE(o.nodes.empty());
    EXPECT_EQ(o.nodes.size(), o.likelihood.size());
  }
  EXPECT_NEAR(c.obs[0].position.x, 20.0, 1e-3);
  EXPECT_NEAR(c.obs[0].position.y, -20.0, 1e-3);
  EXPECT_NEAR(c.obs[1].position.x, 20.5, 1e-3);
  EXPECT_TRUE(c.obs[1].has_velocity);  // two fixes: 0.5 m in 1 s
  EXPECT_NEAR(c.obs[1].velocity.x, 0.5, 1e-3);
  // Diagnostics: rejections by kind (no_fix/not_finite/negative_cov/out_of_order/jump/off_map).
  ASSERT_TRUE(ranging_test::waitFor([&] {
    return c.diag["picker_1 rejected no_fix/not_finite/negative_cov/out_of_order/jump/off_map"] ==
               "1/1/1/2/0/5" &&
           c.diag["picker_1 accepted"] == "2";
  })) << c.diag["picker_1 rejected no_fix/not_finite/negative_cov/out_of_order/jump/off_map"];
  EXPECT_EQ(c.diag["picker_1 accepted"], "2");  // the fix after the 2100 one was accepted: nothing blocked
  EXPECT_EQ(c.diag["fixes stamped in the future (rejected)"], "1");
}

// Issue "Find the lane": anonymous people near a picker's fix become that picker's observations, and the
// sightings teach gnss_ingest the unit's bias, which later fixes have removed.
TEST(GnssIngestNode, PeopleNearAPickerIdentifyItAndRemoveItsGnssBias) {
  namespace pl = picker_localisation;
  ros::NodeHandle nh;
  ranging_test::Collector c(nh, "GNSS ingestion");
  const GeodeticDatum datum = shippedDatum();
  const pl::topology::TopologicalMap map = shippedMap();
  std::vector<pl::GnssBias> bias;
  ros::Subscriber bias_sub = nh.subscribe<pl::GnssBias>(
      "/pickers/picker_3/gnss_bias", 20, [&](const pl::GnssBias::ConstPtr& m) { bias.push_back(*m); });
  ros::Publisher fixes = nh.advertise<sensor_msgs::NavSatFix>("/pickers/picker_3/fix", 20);
  ros::Publisher people = nh.advertise<pl::Observation>("/person_observations", 20);
  ASSERT_TRUE(ranging_test::waitFor([&] {
    return fixes.getNumSubscribers() > 0 && people.getNumSubscribers() > 0 && bias_sub.getNumPublishers() > 0;
  }, 30.0));
  const Eigen::Vector2d truth = kPicker3Truth, offset = kPicker3Offset;
  auto person = [&](const Eigen::Vector2d& at, const ros::Time& stamp) { return personAt(map, at, stamp); };
  auto lidar = [&](bool identifying) {
    std::size_t n = 0;
    for (const auto& o : c.obs) n += o.sensor == "lidar" && o.identifying == identifying;
    return n;
  };
  // Each fix before its person and each person (its sighting) before the next fix: wait for the fix's bias
  // message and the person's identified observation (a fixed pause could let them overtake each other).
  const ros::Time t0 = ros::Time::now();
  for (std::size_t k = 0; k < 6; ++k) {
    const ros::Time t = t0 + ros::Duration(static_cast<double>(k));
    fixes.publish(fixAt(datum, truth + offset, t));
    ASSERT_TRUE(ranging_test::waitFor([&] { return bias.size() >= k + 1; }))
        << "no bias message for fix " << k;
    people.publish(person(truth, t + ros::Duration(0.1)));
    ASSERT_TRUE(ranging_test::waitFor([&] { return lidar(true) >= k + 1; }))
        << "person " << k << " not identified";
  }
  // Far from every picker's prediction: nobody we track, not published (counted as "nobody's").
  people.publish(person(Eigen::Vector2d(300.0, 300.0), t0 + ros::Duration(6.0)));
  fixes.publish(fixAt(datum, truth + offset, t0 + ros::Duration(7.0)));
  ASSERT_TRUE(ranging_test::waitFor([&] { return lidar(true) >= 6 && bias.size() >= 7; }))
      << lidar(true) << " identified, " << lidar(false) << " anonymous, " << bias.size() << " bias messages";
  EXPECT_EQ(lidar(true), 6u);
  EXPECT_EQ(lidar(false), 0u);
  for (const auto& o : c.obs)
    if (o.sensor == "lidar" && o.identifying) {
      EXPECT_EQ(o.picker_id, "picker_3");
    }
  EXPECT_FALSE(bias.front().estimated);  // the first fix came before any sighting
  const pl::GnssBias& last = bias.back();
  EXPECT_TRUE(last.estimated);
  EXPECT_NEAR(last.bias.x, offset.x(), 0.5);
  EXPECT_NEAR(last.bias.y, offset.y(), 0.5);
  EXPECT_GE(last.sightings, 5u);
  EXPECT_LT(last.covariance[0], 1.0);
  // The last fix is published with the bias removed.
  const pl::Observation* fix = nullptr;
  for (const auto& o : c.obs)
    if (o.sensor == "gnss" && o.picker_id == "picker_3") fix = &o;
  ASSERT_NE(fix, nullptr);
  EXPECT_NEAR(fix->position.x, truth.x(), 0.5);
  EXPECT_NEAR(fix->position.y, truth.y(), 0.5);
  ASSERT_TRUE(ranging_test::waitFor([&] {
    return c.diag["picker_3 bias sightings accepted/refused"].rfind("6/", 0) == 0 &&
           c.diag["people received / identified / nobody's / malformed"] == "7 / 6 / 1 / 0";
  })) << c.diag["picker_3 bias sightings accepted/refused"]
      << "; people " << c.diag["people received / identified / nobody's / malformed"];
}

// Issue "Drop-in on an LCAS robot": a picker position already in the map frame (PoseWithCovarianceStamped) is an
// identifying observation; one in another frame is dropped and counted. People of another detector
// (PoseArray, as bayes_people_tracker publishes) go through the same association as the LiDAR's.
TEST(GnssIngestNode, MapFramePosesAndOtherDetectorsPeople) {
  namespace pl = picker_localisation;
  ros::NodeHandle nh;
  ranging_test::Collector c(nh, "GNSS ingestion");
  const GeodeticDatum datum = shippedDatum();
  const pl::topology::TopologicalMap map = shippedMap();
  ros::Publisher pose = nh.advertise<geometry_msgs::PoseWithCovarianceStamped>("/pickers/picker_2/pose", 5);
  ros::Publisher people = nh.advertise<geometry_msgs::PoseArray>("/people_tracker/pose_array", 5);
  ros::Publisher fixes = nh.advertise<sensor_msgs::NavSatFix>("/pickers/picker_3/fix", 20);
  ASSERT_TRUE(ranging_test::waitFor([&] {
    return pose.getNumSubscribers() > 0 && people.getNumSubscribers() > 0 && fixes.getNumSubscribers() > 0;
  }, 30.0));
  const pl::topology::NodeIndex node = map.laneNodes(2)[4];
  geometry_msgs::PoseWithCovarianceStamped p;
  p.header.stamp = ros::Time::now();
  p.header.frame_id = "map";
  p.pose.pose.position.x = map.position2d(node).x();
  p.pose.pose.position.y = map.position2d(node).y();
  p.pose.pose.orientation.w = 1.0;
  p.pose.covariance[0] = p.pose.covariance[7] = 0.25;
  pose.publish(p);
  p.header.frame_id = "odom";  // not the map frame: dropped
  pose.publish(p);
  auto bySensor = [&](const std::string& sensor) {
    const pl::Observation* found = nullptr;
    for (const auto& o : c.obs)
      if (o.sensor == sensor) found = &o;
    return found;
  };
  ASSERT_TRUE(ranging_test::waitFor([&] { return bySensor("pose") != nullptr; })) << "no pose observation";
  const pl::Observation& o = *bySensor("pose");
  EXPECT_TRUE(o.identifying);
  EXPECT_EQ(o.picker_id, "picker_2");
  EXPECT_NEAR(o.position.x, map.position2d(node).x(), 1e-9);
  std::size_t best = 0;
  for (std::size_t k = 1; k < o.likelihood.size(); ++k)
    if (o.likelihood[k] > o.likelihood[best]) best = k;
  EXPECT_EQ(o.nodes.at(best), map.node(node).name);
  ASSERT_TRUE(ranging_test::waitFor([&] { return c.diag["picker poses published / dropped"] == "1 / 1"; }))
      << c.diag["picker poses published / dropped"];

  // picker_3's unit reads (3, 2) m off and its bias is known from the test before: a person of the other
  // detector where picker_3 really is names picker_3; one far from everybody is nobody's.
  const Eigen::Vector2d truth = kPicker3Truth, offset = kPicker3Offset;
  const ros::Time t = ros::Time::now();
  fixes.publish(fixAt(datum, truth + offset, t));
  ranging_test::spinFor(0.3);
  geometry_msgs::PoseArray a;
  a.header.stamp = t + ros::Duration(0.1);
  a.header.frame_id = "map";
  a.poses.resize(2);
  a.poses[0].position.x = truth.x();
  a.poses[0].position.y = truth.y();
  a.poses[1].position.x = 300.0;
  a.poses[1].position.y = 300.0;
  people.publish(a);
  ASSERT_TRUE(ranging_test::waitFor([&] { return bySensor("people") != nullptr; }))
      << "no people observation";
  EXPECT_TRUE(bySensor("people")->identifying);
  EXPECT_EQ(bySensor("people")->picker_id, "picker_3");
}

// Issue "Track a whole farm": gnss_ingest follows the tracker's picker list (/pickers/registry): a picker
// added at run time has its fixes ingested, one removed is no longer subscribed.
TEST(GnssIngestNode, FollowsThePickerListOfTheTracker) {
  namespace pl = picker_localisation;
  ros::NodeHandle nh;
  ranging_test::Collector c(nh, "GNSS ingestion");
  const GeodeticDatum datum = shippedDatum();
  ros::Publisher registry = nh.advertise<pl::PickerList>("/pickers/registry", 1, true);
  ros::Publisher fix4 = nh.advertise<sensor_msgs::NavSatFix>("/pickers/picker_4/fix", 20);
  ros::Publisher fix1 = nh.advertise<sensor_msgs::NavSatFix>("/pickers/picker_1/fix", 20);
  ASSERT_TRUE(ranging_test::waitFor([&] { return registry.getNumSubscribers() > 0 && fix1.getNumSubscribers() > 0; }, 30.0));
  EXPECT_EQ(fix4.getNumSubscribers(), 0u);  // not in the pickers file
  auto info = [](const std::string& id, const std::string& topic) {
    pl::PickerInfo p;
    p.id = id;
    p.gnss_topic = topic;
    return p;
  };
  // An invalid list (an id no topic can carry) is ignored whole: nothing changes.
  pl::PickerList list;
  list.pickers = {info("picker_1", "/pickers/picker_1/fix"), info("picker_4", "/pickers/picker_4/fix"),
                  info("bad-id", "/pickers/bad/fix")};
  registry.publish(list);
  ranging_test::spinFor(1.0);
  EXPECT_EQ(fix4.getNumSubscribers(), 0u);
  EXPECT_GT(fix1.getNumSubscribers(), 0u);
  list.pickers.pop_back();
  registry.publish(list);
  ASSERT_TRUE(ranging_test::waitFor([&] { return fix4.getNumSubscribers() > 0; }))
      << "picker_4 not subscribed";
  ranging_test::spinFor(0.3);
  const std::size_t before = c.obs.size();
  fix4.publish(fixAt(datum, Eigen::Vector2d(20.0, -20.0), ros::Time::now()));
  ASSERT_TRUE(ranging_test::waitFor([&] { return ranging_test::countFor(c.obs, "picker_4") == 1; }));
  EXPECT_GT(c.obs.size(), before);
  // picker_2 and picker_3 are not in the list: no longer subscribed. An empty list removes everyone.
  ros::Publisher fix2 = nh.advertise<sensor_msgs::NavSatFix>("/pickers/picker_2/fix", 20);
  ranging_test::spinFor(1.0);
  EXPECT_EQ(fix2.getNumSubscribers(), 0u);
  list.pickers.clear();
  registry.publish(list);
  ASSERT_TRUE(
      ranging_test::waitFor([&] { return fix4.getNumSubscribers() == 0 && fix1.getNumSubscribers() == 0; }));
  // Back to the file's three pickers for any later test.
  list.pickers = {info("picker_1", "/pickers/picker_1/fix"), info("picker_2", "/pickers/picker_2/fix"),
                  info("picker_3", "/pickers/picker_3/fix")};
  registry.publish(list);
  ASSERT_TRUE(ranging_test::waitFor([&] { return fix1.getNumSubscribers() > 0; }));
}

// With stamp ordering (ordering_latency > 0; gnss_ingest_ordered.test runs this test alone), the people one
// robot's laser saw at one stamp are associated together: each picker is at most one of them. picker_3's bias
// is taught first (its prediction sharp), then two people 1.6 m apart next to it share a stamp. Alone, each
// would be picker_3 (nobody else is near); together only the one where picker_3 stands is.
TEST(GnssIngestNode, PeopleOfOneScanAreNeverTheSamePicker) {
  namespace pl = picker_localisation;
  ros::NodeHandle nh;
  ranging_test::Collector c(nh, "GNSS ingestion");
  const GeodeticDatum datum = shippedDatum();
  const pl::topology::TopologicalMap map = shippedMap();
  ros::Publisher fixes = nh.advertise<sensor_msgs::NavSatFix>("/pickers/picker_3/fix", 20);
  ros::Publisher people = nh.advertise<pl::Observation>("/person_observations", 20);
  ASSERT_TRUE(ranging_test::waitFor(
      [&] {
        return fixes.getNumSubscribers() > 0 && people.getNumSubscribers() > 0 &&
               c.obs_sub.getNumPublishers() > 0;
      },
      30.0));
  auto identified = [&](const std::string& id) {
    std::size_t n = 0;
    for (const auto& o : c.obs) n += o.sensor == "lidar" && o.identifying && o.picker_id == id;
    return n;
  };
  const Eigen::Vector2d truth = kPicker3Truth, offset = kPicker3Offset;
  const ros::Time t0 = ros::Time::now();
  for (std::size_t k = 0; k < 4; ++k) {  // fix, then the person where picker_3 stands: its bias
    const ros::Time t = t0 + ros::Duration(static_cast<double>(k));
    fixes.publish(fixAt(datum, truth + offset, t));
    ranging_test::spinFor(0.05);
    people.publish(personAt(map, truth, t + ros::Duration(0.1)));
    ASSERT_TRUE(ranging_test::waitFor([&] { return identified("picker_3") >= k + 1; }))
        << "person " << k << " not identified";
  }
  // Two people at one stamp of one robot, 1.6 m apart, one where picker_3 stands. Alone, the other would be
  // picker_3 as well (p ~ 0.99: nobody else is near; sensors::associatePerson, test_gnss); together only the
  // one where picker_3 stands is.
  const ros::Time t = t0 + ros::Duration(4.0);
  fixes.publish(fixAt(datum, truth + offset, t));
  ranging_test::spinFor(0.05);
  const std::size_t lidar_before = c.obs.size();
  people.publish(personAt(map, truth + Eigen::Vector2d(0.0, 1.6), t + ros::Duration(0.1)));
  people.publish(personAt(map, truth, t + ros::Duration(0.1)));
  ASSERT_TRUE(ranging_test::waitFor([&] { return identified("picker_3") >= 5; })) << "the pair";
  ranging_test::spinFor(1.0);
  EXPECT_EQ(identified("picker_3"), 5u);
  bool found = false;
  for (std::size_t k = lidar_before; k < c.obs.size(); ++k) {
    const auto& o = c.obs[k];
    if (o.sensor != "lidar" || !o.identifying) continue;
    found = true;
    EXPECT_NEAR(o.position.x, truth.x(), 1e-6);
    EXPECT_NEAR(o.position.y, truth.y(), 1e-6);
  }
  EXPECT_TRUE(found);
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_gnss_ingest_node");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
