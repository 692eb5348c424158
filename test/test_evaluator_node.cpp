// rostest of the evaluator node: the TrackingError it publishes against values computed by hand from the map
// file's node positions, and bad input (unknown estimated node, NaN ground truth) that must be ignored.
#include <geometry_msgs/PoseStamped.h>
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <cmath>

#include "diagnostics_rostest_util.h"
#include "picker_localisation/PickerBelief.h"
#include "picker_localisation/PickerBeliefArray.h"
#include "picker_localisation/TrackingError.h"
#include "picker_localisation/topology/map_io.h"

using namespace picker_localisation;

namespace {

struct Fixture {
  ros::NodeHandle nh;
  // The evaluator reads the trackers' fleet stream (its default ~belief_topic).
  ros::Publisher belief = nh.advertise<picker_localisation::PickerBeliefArray>("/pickers/beliefs", 10, true);
  ros::Publisher truth = nh.advertise<geometry_msgs::PoseStamped>("/pickers/picker_1/ground_truth", 10, true);
  std::vector<picker_localisation::TrackingError> errors;
  ros::Subscriber sub = nh.subscribe<picker_localisation::TrackingError>(
      "/pickers/picker_1/error", 100, [this](const picker_localisation::TrackingError::ConstPtr& m) {
        errors.push_back(*m);
      });

  void sendBelief(const std::string& node) {
    picker_localisation::PickerBelief b;
    b.header.stamp = ros::Time::now();
    b.picker_id = "picker_1";
    b.estimated_node = node;
    picker_localisation::PickerBeliefArray fleet;
    fleet.header = b.header;
    picker_localisation::PickerBelief other = b;  // a picker the evaluator does not score: ignored
    other.picker_id = "not_listed";
    other.estimated_node = "NoSuchNode";
    fleet.beliefs = {other, b};
    belief.publish(fleet);
  }
  void sendTruth(double x, double y) {
    geometry_msgs::PoseStamped p;
    p.header.stamp = ros::Time::now();
    p.header.frame_id = "map";
    p.pose.position.x = x;
    p.pose.position.y = y;
    p.pose.orientation.w = 1.0;
    truth.publish(p);
  }
  // Waits until an error message satisfying `pred` arrives (clearing older ones first); the default deadline
  // is generous, for a loaded machine.
  template <typename Pred>
  bool waitFor(Pred pred, double seconds = test_wait::kDeadline) {
    errors.clear();
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(seconds);
    while (ros::ok() && ros::WallTime::now() < end) {
      ros::spinOnce();
      for (const auto& e : errors)
        if (pred(e)) return true;
      ros::WallDuration(0.02).sleep();
    }
    return false;
  }
};

}  // namespace

TEST(EvaluatorNode, HandComputedErrorsAndBadInput) {
  Fixture f;
  const auto map = topology::loadMap(std::string(PL_PACKAGE_DIR) + "/config/maps/riseholme.tmap2");
  const auto w1 = map.position2d(*map.index("WayPoint1"));
  const auto w2 = map.position2d(*map.index("WayPoint2"));  // WayPoint1 -> WayPoint2 is an edge of the file
  // Estimate WayPoint1, truth exactly on WayPoint2: one hop, the distance between the two nodes.
  f.sendBelief("WayPoint1");
  f.sendTruth(w2.x(), w2.y());
  ASSERT_TRUE(f.waitFor([](const picker_localisation::TrackingError& e) { return e.true_node == "WayPoint2"; }));
  const auto e = f.errors.back();
  EXPECT_EQ(e.picker_id, "picker_1");
  EXPECT_EQ(e.estimated_node, "WayPoint1");
  EXPECT_NEAR(e.euclidean_error, std::hypot(w2.x() - w1.x(), w2.y() - w1.y()), 1e-6);
  EXPECT_EQ(e.topological_error, 1);

  // Estimate on the truth: zero errors, in the true lane.
  f.sendBelief("WayPoint2");
  ASSERT_TRUE(f.waitFor([](const picker_localisation::TrackingError& e) { return e.estimated_node == "WayPoint2"; }));
  EXPECT_NEAR(f.errors.back().euclidean_error, 0.0, 1e-6);
  EXPECT_EQ(f.errors.back().topological_error, 0);
  EXPECT_TRUE(f.errors.back().in_true_lane);

  // Bad input: an unknown node name, a NaN truth and a truth 1,000 km off the map (it was scored against the
  // nearest node) are ignored; the last valid values stay in use.
  f.sendBelief("NoSuchNode");
  f.sendTruth(std::nan(""), 0.0);
  ros::WallDuration(0.2).sleep();
  f.sendTruth(1e6, 0.0);
  ros::WallDuration(0.5).sleep();
  ASSERT_TRUE(f.waitFor([](const picker_localisation::TrackingError&) { return true; }));
  for (const auto& err : f.errors) {
    EXPECT_EQ(err.estimated_node, "WayPoint2");
    EXPECT_EQ(err.true_node, "WayPoint2");
    EXPECT_TRUE(std::isfinite(err.euclidean_error));
  }
}

// After the test above (truth and beliefs received): the inputs status counts them.
TEST(EvaluatorNode, PublishesDiagnosticsWithInputRates) {
  ros::NodeHandle nh;
  const auto seen = diagnostics_test::collect(nh, {"/evaluator"});
  ASSERT_TRUE(seen.count("/evaluator") && seen.at("/evaluator").count("inputs"));
  bool truth = false;
  for (const auto& kv : seen.at("/evaluator").at("inputs").values)
    if (kv.key == "ground truth received / rate [Hz] / newest [s ago]") truth = kv.value.rfind("0 / ", 0) != 0;
  EXPECT_TRUE(truth) << "the ground truth sent above is not counted";
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_evaluator_node");
  return RUN_ALL_TESTS();
}
