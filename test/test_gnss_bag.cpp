// GnssIngest on the real fixes of robot_localization's test1.bag (989 NavSatFix of a Husky in a parking lot,
// status SBAS, covariance type APPROXIMATED; see test/data/README.md). Plain gtest with
// the rosbag C++ API: no master. Datum near the bag's start.
#include <gtest/gtest.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/NavSatFix.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "picker_localisation/ros/ranging_nodes.h"
#include "picker_localisation/sensors_ranging/gnss_ingest.h"
#include "ranging_test_maps.h"

using namespace picker_localisation;
using namespace picker_localisation::sensors;
using picker_localisation::core::DatumConfig;
using picker_localisation::core::GeodeticDatum;

namespace {
const std::string kBag = std::string(PL_TEST_DATA) + "/robot_localization/test1.bag";

}  // namespace

TEST(GnssBag, RealFixesOfTest1Bag) {
  ASSERT_TRUE(std::ifstream(kBag).good()) << "no " << kBag;
  rosbag::Bag bag(kBag, rosbag::bagmode::Read);
  std::vector<sensor_msgs::NavSatFix> fixes;
  double odom_speed_sum = 0.0;
  std::size_t odom_n = 0;
  for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
    if (auto f = m.instantiate<sensor_msgs::NavSatFix>()) fixes.push_back(*f);
    if (auto o = m.instantiate<nav_msgs::Odometry>()) {
      odom_speed_sum += std::abs(o->twist.twist.linear.x);
      ++odom_n;
    }
  }
  ASSERT_EQ(fixes.size(), 989u);
  ASSERT_GT(odom_n, 1000u);
  const double odom_mean_speed = odom_speed_sum / static_cast<double>(odom_n);  // wheel odometry, m/s

  DatumConfig dc;  // datum at the first fix (local tangent plane; map x east, y north)
  dc.latitude = fixes.front().latitude;
  dc.longitude = fixes.front().longitude;
  GeodeticDatum datum(dc);
  auto map = ranging_test::latticeMap(160.0, 4.0);
  GnssIngest gnss("husky", map, datum);

  double min_x = 1e9, max_x = -1e9, min_y = 1e9, max_y = -1e9, speed_sum = 0.0;
  std::vector<double> speeds;
  for (const sensor_msgs::NavSatFix& msg : fixes) {
    GnssResult r = gnss.process(ros_adapter::gnssFixFromMsg(msg));
    ASSERT_TRUE(r.accepted()) << "fix at " << msg.header.stamp << ": " << r.reason;
    min_x = std::min(min_x, r.position.x());
    max_x = std::max(max_x, r.position.x());
    min_y = std::min(min_y, r.position.y());
    max_y = std::max(max_y, r.position.y());
    ASSERT_FALSE(r.observation->nodes.empty());
    // Approximated covariance 0.64 .. 2.89 m^2 -> sigma 0.8 .. 1.7 m (floored at 1 m): the likelihood's support
    // is the lattice nodes within 3 sigma (<= 5.1 m) of the fix.
    for (topology::NodeIndex n : r.observation->nodes)
      ASSERT_LE((map->position2d(n) - r.position).norm(), 3.0 * 1.7 + 1e-6);
    if (r.observation->velocity) {
      speeds.push_back(r.observation->velocity->norm());
      speed_sum += speeds.back();
    }
  }
  // README: "the track spans about 146 m x 58 m" (146 m north-south, 58 m east-west here).
  EXPECT_NEAR(max_y - min_y, 146.0, 4.0);
  EXPECT_NEAR(max_x - min_x, 58.0, 4.0);
  const GnssCounters& c = gnss.counters();
  EXPECT_EQ(c.accepted, 989u);
  EXPECT_EQ(c.impossible_jump, 0u);
  EXPECT_EQ(c.blackouts, 0u);  // largest gap 0.41 s
  // Velocity over the last 10 fixes vs wheel odometry (mean |v| 0.91 m/s): same mean within 25 %, never
  // faster than the Husky's 1 m/s top speed plus GNSS noise.
  ASSERT_EQ(speeds.size(), 988u);
  const double mean_speed = speed_sum / static_cast<double>(speeds.size());
  EXPECT_NEAR(mean_speed, odom_mean_speed, 0.25 * odom_mean_speed);
  std::sort(speeds.begin(), speeds.end());
  EXPECT_LT(speeds[speeds.size() * 95 / 100], 1.6);
  RecordProperty("track_span_x_m", std::to_string(max_x - min_x));
  RecordProperty("track_span_y_m", std::to_string(max_y - min_y));
  RecordProperty("mean_gnss_speed", std::to_string(mean_speed));
  RecordProperty("mean_odom_speed", std::to_string(odom_mean_speed));
  std::printf("test1.bag: span %.1f m x %.1f m, mean GNSS speed %.3f m/s (odometry %.3f m/s), p95 %.3f m/s\n",
              max_x - min_x, max_y - min_y, mean_speed, odom_mean_speed, speeds[speeds.size() * 95 / 100]);
}

TEST(GnssBag, UtmDatumGivesTheSameTrack) {
  ASSERT_TRUE(std::ifstream(kBag).good()) << "no " << kBag;
  rosbag::Bag bag(kBag, rosbag::bagmode::Read);
  std::vector<sensor_msgs::NavSatFix> fixes;
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery("/fix")))
    if (auto f = m.instantiate<sensor_msgs::NavSatFix>()) fixes.push_back(*f);
  ASSERT_FALSE(fixes.empty());
  DatumConfig lc;
  lc.latitude = fixes.front().latitude;
  lc.longitude = fixes.front().longitude;
  const GeodeticDatum local(lc);
  // UTM zone 19 (71.1 W); origin = UTM of the first fix, recovered through the inverse of a provisional datum.
  DatumConfig uc;
  uc.kind = DatumConfig::Kind::kUtm;
  uc.utm_zone = 19;
  const GeodeticDatum provisional(uc);
  const Eigen::Vector2d origin = provisional.toMap(lc.latitude, lc.longitude);
  uc.utm_easting = origin.x();
  uc.utm_northing = origin.y();
  const GeodeticDatum utm(uc);
  // Same distances (scale factor ~0.9997 here; convergence rotates by ~1.3 deg: compare norms).
  for (const sensor_msgs::NavSatFix& f : fixes) {
    const double a = local.toMap(f.latitude, f.longitude).norm(), b = utm.toMap(f.latitude, f.longitude).norm();
    EXPECT_NEAR(a, b, 0.05 + 1e-3 * a);
  }
}
