// rostest: rfid_ranging through ROS. Unknown tag, missing tf (unknown and empty antenna frame), a NaN RSSI, a
// read stamped in 2100 and a stamp going backwards publish nothing and do not stop the node; good reads before and after become identifying
// Observations over the nodes within read range of the antenna's tf pose; negative information for the
// pickers not read; diagnostics count the drops.
#include <geometry_msgs/TransformStamped.h>
#include <gtest/gtest.h>
#include <picker_localisation/PickerList.h>
#include <picker_localisation/RfidReading.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include <cmath>

#include "ranging_rostest_util.h"

namespace {
picker_localisation::RfidReading reading(const std::string& tag, const std::string& frame, const ros::Time& stamp) {
  picker_localisation::RfidReading r;
  r.header.stamp = stamp;
  r.header.frame_id = frame;
  r.robot_id = "robot_1";
  r.tag_id = tag;
  r.rssi = -55.0;
  return r;
}
}  // namespace

TEST(RfidRangingNode, BadReadsAreDroppedAndGoodOnesStillPublish) {
  ros::NodeHandle nh;
  ranging_test::Collector c(nh, "RFID ranging");
  tf2_ros::StaticTransformBroadcaster tf;
  geometry_msgs::TransformStamped t;
  t.header.stamp = ros::Time::now();
  t.header.frame_id = "map";
  t.child_frame_id = "robot_1/rfid_antenna";
  t.transform.translation.x = 20.0;
  t.transform.translation.y = -20.0;
  t.transform.rotation.w = 1.0;
  tf.sendTransform(t);
  ros::Publisher pub = nh.advertise<picker_localisation::RfidReading>("/robot_1/rfid", 50);
  ASSERT_TRUE(ranging_test::waitFor([&] { return pub.getNumSubscribers() > 0 && c.obs_sub.getNumPublishers() > 0; }, 30.0));
  ranging_test::spinFor(0.5);  // let the node's tf listener receive the static transform
  const ros::Time t0 = ros::Time::now();
  auto send = [&](const picker_localisation::RfidReading& r, double wait = 0.05) {
    pub.publish(r);
    ranging_test::spinFor(wait);
  };
  send(reading("stranger", "robot_1/rfid_antenna", t0));  // unknown tag
  send(reading("rfid_0001", "robot_1/ghost", t0), 0.4);    // no tf for this frame: bounded wait, dropped
  send(reading("rfid_0001", "", t0));                      // empty frame
  picker_localisation::RfidReading nan_rssi = reading("rfid_0001", "robot_1/rfid_antenna", t0);
  nan_rssi.rssi = std::nan("");
  send(nan_rssi);                                                                   // corrupted RSSI
  send(reading("rfid_0001", "robot_1/rfid_antenna", ros::Time(4102444800.0)));      // 2100: never adopted
  send(reading("rfid_0001", "robot_1/rfid_antenna", t0));  // good
  ASSERT_TRUE(ranging_test::waitFor([&] { return c.obs.size() >= 1; }));
  send(reading("rfid_0001", "robot_1/rfid_antenna", t0 - ros::Duration(2.0)));  // backwards
  for (int i = 1; i <= 6; ++i) send(reading("rfid_0001", "robot_1/rfid_antenna", t0 + ros::Duration(0.25 * i)));
  // 7 positives for picker_1; after 1 s of reading, one negative each for picker_2 and picker_3.
  ASSERT_TRUE(ranging_test::waitFor([&] { return c.obs.size() >= 9; }));
  ranging_test::spinFor(0.5);
  ASSERT_EQ(c.obs.size(), 9u);
  EXPECT_EQ(ranging_test::countFor(c.obs, "picker_1"), 7u);
  EXPECT_EQ(ranging_test::countFor(c.obs, "picker_2"), 1u);
  EXPECT_EQ(ranging_test::countFor(c.obs, "picker_3"), 1u);
  for (const auto& o : c.obs) {
    EXPECT_TRUE(o.identifying);
    EXPECT_EQ(o.sensor, "rfid");
    EXPECT_EQ(o.robot_id, "robot_1");
    ASSERT_EQ(o.nodes.size(), o.likelihood.size());
    if (o.picker_id == "picker_1") {
      EXPECT_NEAR(o.position.x, 20.0, 1e-9);
      EXPECT_NEAR(o.position.y, -20.0, 1e-9);
      // Logistic read model with failed attempts (config/rfid_ranging.yaml):
      // L(n) = p_read(d(n)) (1 - p_read(d(n)))^m in (0, p_max], m = 10 for the tag's first read.
      for (double l : o.likelihood) {
        EXPECT_GT(l, 0.0);
        EXPECT_LE(l, 0.95);
      }
    } else {
      EXPECT_EQ(o.nodes.size(), 138u);  // negative: every node of the Riseholme map
      // 1 - p_detect p_read(d) / p_max >= 1 - p_detect = 0.3 (equality only for a node at the antenna).
      const double lo = *std::min_element(o.likelihood.begin(), o.likelihood.end());
      EXPECT_GE(lo, 0.3 - 1e-9);
      EXPECT_LT(lo, 1.0);
    }
  }
  // Wait for a 1 Hz status taken after the last bad read (the backwards one), not one from before it.
  ASSERT_TRUE(ranging_test::waitFor([&] {
    return c.diag["dropped: no tf"] == "2" && c.diag["rejected: out of order"] == "1";
  })) << c.diag["dropped: no tf"]
      << " / " << c.diag["rejected: out of order"];
  EXPECT_EQ(c.diag["rejected: unknown tag"], "1");
  EXPECT_EQ(c.diag["rejected: out of order"], "1");
  EXPECT_EQ(c.diag["rejected: not finite"], "1");
  EXPECT_EQ(c.diag["stamped in the future (dropped)"], "1");
}

// A picker added to the tracker at run time (its list on /pickers/registry): its tag is read as its own.
// A front-end whose input topic stays silent (a misspelt name) must not look green.
TEST(RfidRangingNode, SilentInputGoesWarn) {
  ros::NodeHandle nh;
  diagnostic_msgs::DiagnosticStatus quiet;
  ros::Subscriber sub = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 10, [&](const diagnostic_msgs::DiagnosticArray::ConstPtr& m) {
        for (const auto& s : m->status)
          if (s.name.find("robot_2") != std::string::npos && s.name.find("RFID ranging") != std::string::npos)
            quiet = s;
      });
  ASSERT_TRUE(ranging_test::waitFor([&] { return quiet.level == diagnostic_msgs::DiagnosticStatus::WARN; }))
      << "robot_2's rfid_ranging reports '" << quiet.message << "' (level " << int(quiet.level) << ")";
  EXPECT_NE(quiet.message.find("RFID reads: nothing for"), std::string::npos) << quiet.message;
  EXPECT_NE(quiet.message.find("check the topic names"), std::string::npos) << quiet.message;
}

TEST(RfidRangingNode, FollowsThePickerListOfTheTracker) {
  ros::NodeHandle nh;
  ranging_test::Collector c(nh, "RFID ranging");
  ros::Publisher registry = nh.advertise<picker_localisation::PickerList>("/pickers/registry", 1, true);
  ros::Publisher pub = nh.advertise<picker_localisation::RfidReading>("/robot_1/rfid", 50);
  ASSERT_TRUE(ranging_test::waitFor([&] { return pub.getNumSubscribers() > 0 && registry.getNumSubscribers() > 0; }, 30.0));
  picker_localisation::PickerList list;
  for (const auto& [id, tag] : std::vector<std::pair<std::string, std::string>>{{"picker_1", "rfid_0001"},
                                                                                {"picker_9", "stranger"}}) {
    picker_localisation::PickerInfo p;
    p.id = id;
    p.rfid_tags = {tag};
    list.pickers.push_back(p);
  }
  registry.publish(list);
  // A read of the added picker's tag, repeated until the node has taken the list (however slow the machine).
  ASSERT_TRUE(ranging_test::waitFor([&] {
    pub.publish(reading("stranger", "robot_1/rfid_antenna", ros::Time::now() + ros::Duration(5.0)));
    ranging_test::spinFor(0.5);
    return ranging_test::countFor(c.obs, "picker_9") >= 1;
  })) << "a read of the added picker's tag was not published as its observation";
  for (const auto& o : c.obs)
    if (o.picker_id == "picker_9") {
      EXPECT_TRUE(o.identifying);
      EXPECT_NEAR(o.position.x, 20.0, 1e-9);
    }
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_rfid_ranging_node");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
