// rostest: gnss_ingest through ROS. Bad fixes (NaN, NO_FIX, negative covariance, repeated and backwards
// stamps) publish nothing and do not stop the node; good fixes before and after become identifying
// Observations at the right place; diagnostics count the rejections.
#include <gtest/gtest.h>
#include <sensor_msgs/NavSatFix.h>

#include <cmath>

#include "picker_localisation/sensors_ranging/geodetic_datum.h"
#include "ranging_rostest_util.h"

using picker_localisation::sensors::GeodeticDatum;

using ranging_test::fixAt;

TEST(GnssIngestNode, BadFixesAreRejectedAndGoodOnesStillPublish) {
  ros::NodeHandle nh;
  ranging_test::Collector c(nh, "GNSS ingestion");
  const GeodeticDatum datum = GeodeticDatum::load(std::string(PL_PACKAGE_DIR) + "/config/datum.yaml");
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
  ASSERT_TRUE(ranging_test::waitFor([&] { return c.obs.size() >= 1; }, 10.0));
  send(p1, fixAt(datum, where, t0));                                        // repeated stamp
  send(p1, fixAt(datum, where, t0 - ros::Duration(1.0)));                   // backwards
  send(p1, fixAt(datum, where, ros::Time(4102444800.0)));                   // 2100-01-01: far future, dropped
  send(p1, fixAt(datum, where + Eigen::Vector2d(0.5, 0.0), t0 + ros::Duration(1.0)));  // good again
  send(p2, fixAt(datum, Eigen::Vector2d(25.0, -30.0), t0 + ros::Duration(1.0)));       // other picker
  ASSERT_TRUE(ranging_test::waitFor([&] { return c.obs.size() >= 3; }, 10.0));
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
  // Diagnostics: rejections by kind (no_fix/not_finite/negative_cov/out_of_order/jump).
  ASSERT_TRUE(ranging_test::waitFor(
      [&] { return c.diag["picker_1 rejected no_fix/not_finite/negative_cov/out_of_order/jump"] == "1/1/1/2/0"; }, 5.0))
      << c.diag["picker_1 rejected no_fix/not_finite/negative_cov/out_of_order/jump"];
  EXPECT_EQ(c.diag["picker_1 accepted"], "2");  // the fix after the 2100 one was accepted: nothing blocked
  EXPECT_EQ(c.diag["fixes stamped in the future (rejected)"], "1");
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_gnss_ingest_node");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
