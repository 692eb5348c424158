// rostest of tpf_tracker (one node, the three pickers of test/data/tpf_test_pickers.yaml, via
// launch/trackers.launch): beliefs / estimates / markers on observations, another picker's identifying
// observations ignored, non-identifying ones reaching every filter, periodic prediction, what-if leaving the
// live filter alone, reset, bad input; pickers added and removed at run time (and bad requests refused).
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <picker_localisation/AddPicker.h>
#include <picker_localisation/ListPickers.h>
#include <picker_localisation/Observation.h>
#include <picker_localisation/PickerBelief.h>
#include <picker_localisation/PickerList.h>
#include <picker_localisation/RemovePicker.h>
#include <picker_localisation/ResetBelief.h>
#include <picker_localisation/WhatIf.h>
#include <visualization_msgs/MarkerArray.h>

#include <cmath>
#include <set>
#include <map>
#include <memory>

#include "picker_localisation/ros/observation_conversions.h"
#include "picker_localisation/topology/map_io.h"
#include "wait_deadline.h"

using namespace picker_localisation;

namespace {

struct PickerTopics {
  std::vector<PickerBelief> beliefs;
  std::vector<geometry_msgs::PoseWithCovarianceStamped> estimates;
  std::vector<visualization_msgs::MarkerArray> markers;
};

class TrackerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    map_ = std::make_shared<topology::TopologicalMap>(
        topology::loadMap(std::string(PL_PACKAGE_DIR) + "/config/maps/riseholme.tmap2"));
    pub_ = nh_.advertise<picker_localisation::Observation>("/observations", 50);
    for (const std::string id : {"picker_1", "picker_2", "picker_3"}) {
      subs_.push_back(nh_.subscribe<PickerBelief>(
          "/pickers/" + id + "/belief", 50,
          [this, id](const PickerBelief::ConstPtr& m) { topics_[id].beliefs.push_back(*m); }));
      subs_.push_back(nh_.subscribe<geometry_msgs::PoseWithCovarianceStamped>(
          "/pickers/" + id + "/estimate", 50,
          [this, id](const geometry_msgs::PoseWithCovarianceStamped::ConstPtr& m) {
            topics_[id].estimates.push_back(*m);
          }));
      subs_.push_back(nh_.subscribe<visualization_msgs::MarkerArray>(
          "/pickers/" + id + "/markers", 50, [this, id](const visualization_msgs::MarkerArray::ConstPtr& m) {
            topics_[id].markers.push_back(*m);
          }));
      ASSERT_TRUE(ros::service::waitForService("/pickers/" + id + "/what_if", ros::Duration(60.0))) << id;
    }
    // Per-picker topics come on demand (on_demand_topics_above 2): these subscriptions bring them up.
    for (const auto& sub : subs_) {
      const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(30.0);
      while (sub.getNumPublishers() == 0 && ros::WallTime::now() < deadline) ros::WallDuration(0.05).sleep();
      ASSERT_GT(sub.getNumPublishers(), 0u) << sub.getTopic() << " was not advertised for its subscriber";
    }
    // One node tracks every picker: one subscription to /observations.
    const ros::WallTime until = ros::WallTime::now() + ros::WallDuration(30.0);
    while (pub_.getNumSubscribers() < 1 && ros::WallTime::now() < until) ros::WallDuration(0.05).sleep();
    ASSERT_EQ(pub_.getNumSubscribers(), 1u);
    spinFor(0.5);  // latched messages of the start
  }

  void spinFor(double seconds) {
    const ros::WallTime until = ros::WallTime::now() + ros::WallDuration(seconds);
    while (ros::WallTime::now() < until) {
      ros::spinOnce();
      ros::WallDuration(0.01).sleep();
    }
  }
  // Default deadline: generous, for a loaded machine (the wait ends as soon as pred() holds).
  template <typename Pred>
  bool waitFor(Pred pred, double seconds = test_wait::kDeadline) {
    const ros::WallTime until = ros::WallTime::now() + ros::WallDuration(seconds);
    while (ros::WallTime::now() < until) {
      ros::spinOnce();
      if (pred()) return true;
      ros::WallDuration(0.01).sleep();
    }
    return pred();
  }

  // An observation centred on a node (Gaussian likelihood, sigma 1 m).
  core::Observation observationAt(const std::string& node, const std::string& sensor,
                                  const std::string& picker) {
    core::Observation o;
    o.stamp = ros::Time::now().toSec();
    o.sensor = sensor;
    o.identifying = !picker.empty();
    o.picker_id = picker;
    core::setGaussianLikelihood(o, *map_, map_->position2d(*map_->index(node)), Eigen::Matrix2d::Identity());
    return o;
  }
  void send(const core::Observation& o) { pub_.publish(ros_adapter::toMsg(o, *map_)); }
  int hops(const std::string& a, const std::string& b) {
    return map_->hopDistance(*map_->index(a), *map_->index(b));
  }

  ros::NodeHandle nh_;
  std::shared_ptr<topology::TopologicalMap> map_;
  ros::Publisher pub_;
  std::vector<ros::Subscriber> subs_;
  std::map<std::string, PickerTopics> topics_;
};

// Two nodes of different lanes, far apart.
std::pair<std::string, std::string> farNodes(const topology::TopologicalMap& map) {
  topology::NodeIndex a = map.laneNodes(0).front();
  topology::NodeIndex b = a;
  for (topology::NodeIndex n = 0; n < map.numNodes(); ++n)
    if (map.hopDistance(a, n) > map.hopDistance(a, b)) b = n;
  return {map.node(a).name, map.node(b).name};
}

TEST_F(TrackerTest, BeliefEstimateRoutingServicesAndBadInput) {
  const auto [node_a, node_b] = farNodes(*map_);
  ASSERT_GT(hops(node_a, node_b), 4);

  // 1. picker_1's GNSS at node A: belief, estimate and markers of picker_1 near A.
  for (int k = 0; k < 3; ++k) {
    send(observationAt(node_a, "gnss", "picker_1"));
    spinFor(0.2);
  }
  ASSERT_TRUE(waitFor([&] { return topics_["picker_1"].beliefs.size() >= 3; }));
  const PickerBelief b1 = topics_["picker_1"].beliefs.back();
  EXPECT_EQ(b1.picker_id, "picker_1");
  EXPECT_LE(hops(b1.estimated_node, node_a), 1);
  EXPECT_EQ(b1.particle_count, 500u);  // per-picker override from the pickers file
  EXPECT_EQ(b1.nodes.size(), b1.masses.size());
  double total = 0.0;
  for (double m : b1.masses) total += m;
  EXPECT_NEAR(total, 1.0, 1e-6);
  EXPECT_EQ(b1.header.frame_id, "map");
  ASSERT_FALSE(topics_["picker_1"].estimates.empty());
  const auto& est = topics_["picker_1"].estimates.back().pose.pose.position;
  EXPECT_NEAR(est.x, map_->node(*map_->index(b1.estimated_node)).position.x(), 1e-9);
  ASSERT_FALSE(topics_["picker_1"].markers.empty());
  ASSERT_FALSE(topics_["picker_1"].markers.back().markers.empty());
  EXPECT_EQ(topics_["picker_1"].markers.back().markers[0].points.size(), b1.nodes.size());
  // picker_2 and picker_3 got nothing identifying: no belief beyond the latched start-up one.
  for (const auto& b : topics_["picker_2"].beliefs) EXPECT_EQ(b.observations, 0u);

  // 2. picker_2's identifying GNSS at node B never reaches picker_1.
  const std::size_t p1_count = topics_["picker_1"].beliefs.size();
  send(observationAt(node_b, "gnss", "picker_2"));
  ASSERT_TRUE(waitFor([&] {
    return !topics_["picker_2"].beliefs.empty() && topics_["picker_2"].beliefs.back().observations == 1;
  }));
  EXPECT_LE(hops(topics_["picker_2"].beliefs.back().estimated_node, node_b), 1);
  spinFor(0.2);
  for (std::size_t k = p1_count; k < topics_["picker_1"].beliefs.size(); ++k)
    EXPECT_EQ(topics_["picker_1"].beliefs[k].observations, b1.observations)
        << "picker_1 fused picker_2's fix";

  // 3. A non-identifying LiDAR detection at A reaches every tracker (picker_3 initialises from it).
  send(observationAt(node_a, "lidar", ""));
  ASSERT_TRUE(waitFor([&] {
    return !topics_["picker_3"].beliefs.empty() && topics_["picker_3"].beliefs.back().observations == 1 &&
           topics_["picker_1"].beliefs.back().observations == b1.observations + 1;
  }));

  // 3b. An unidentified detection that names its candidate pickers (gnss_ingest's association) reaches only
  // those: picker_3 fuses it, picker_1 does not.
  {
    core::Observation only3 = observationAt(node_a, "lidar", "");
    only3.candidate_pickers = {"picker_3"};
    const std::uint32_t p1 = topics_["picker_1"].beliefs.back().observations;
    send(only3);
    ASSERT_TRUE(waitFor([&] { return topics_["picker_3"].beliefs.back().observations == 2; }));
    spinFor(0.3);
    EXPECT_EQ(topics_["picker_1"].beliefs.back().observations, p1) << "picker_1 fused picker_3's candidate";
  }

  // 4. Periodic prediction (picker_1 at 2 Hz) without observations: newer stamps, same observation count.
  const double last_stamp = topics_["picker_1"].beliefs.back().header.stamp.toSec();
  ASSERT_TRUE(
      waitFor([&] { return topics_["picker_1"].beliefs.back().header.stamp.toSec() > last_stamp + 0.4; }));
  EXPECT_EQ(topics_["picker_1"].beliefs.back().observations, b1.observations + 1);

  // 5. What-if: predict ahead, and posterior under a hypothetical observation at B; the live filter stays.
  ros::ServiceClient what_if = nh_.serviceClient<picker_localisation::WhatIf>("/pickers/picker_1/what_if");
  picker_localisation::WhatIf ahead;
  ahead.request.horizon = 4.0;
  ahead.request.seed = 7;
  ASSERT_TRUE(what_if.call(ahead));
  ASSERT_TRUE(ahead.response.success) << ahead.response.message;
  picker_localisation::WhatIf hyp;
  hyp.request.horizon = 1.0;
  hyp.request.with_observation = true;
  hyp.request.observation = ros_adapter::toMsg(observationAt(node_b, "gnss", "picker_1"), *map_);
  hyp.request.seed = 7;
  ASSERT_TRUE(what_if.call(hyp));
  ASSERT_TRUE(hyp.response.success) << hyp.response.message;
  EXPECT_LE(hops(hyp.response.belief.estimated_node, node_b), 1);
  picker_localisation::WhatIf now;  // horizon 0: the live belief
  ASSERT_TRUE(what_if.call(now));
  EXPECT_LE(hops(now.response.belief.estimated_node, node_a), 1);
  EXPECT_EQ(now.response.belief.observations, b1.observations + 1);
  picker_localisation::WhatIf bad_horizon;
  bad_horizon.request.horizon = -1.0;
  ASSERT_TRUE(what_if.call(bad_horizon));
  EXPECT_FALSE(bad_horizon.response.success);

  // 6. Bad input: NaN likelihood, unknown node names, a stale stamp: rejected, tracker alive, belief kept.
  picker_localisation::Observation bad = ros_adapter::toMsg(observationAt(node_a, "gnss", "picker_1"), *map_);
  bad.likelihood[0] = std::nan("");
  pub_.publish(bad);
  picker_localisation::Observation unknown =
      ros_adapter::toMsg(observationAt(node_a, "gnss", "picker_1"), *map_);
  for (auto& n : unknown.nodes) n = "no_such_node_" + n;
  pub_.publish(unknown);
  picker_localisation::Observation stale =
      ros_adapter::toMsg(observationAt(node_b, "gnss", "picker_1"), *map_);
  stale.header.stamp = ros::Time(1.0);
  pub_.publish(stale);
  // A stamp in 2100: dropped (adopting it would block every later observation and start ~6e8 predictions).
  picker_localisation::Observation future =
      ros_adapter::toMsg(observationAt(node_b, "gnss", "picker_1"), *map_);
  future.header.stamp = ros::Time(4102444800.0);
  pub_.publish(future);
  spinFor(0.5);
  picker_localisation::WhatIf after;
  ASSERT_TRUE(what_if.call(after));
  EXPECT_EQ(after.response.belief.observations, b1.observations + 1);
  EXPECT_LE(hops(after.response.belief.estimated_node, node_a), 1);

  // 7. Diagnostics: picker_1's status with its counters, WARN after the rejected input above.
  std::vector<diagnostic_msgs::DiagnosticStatus> statuses;
  ros::Subscriber diag = nh_.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 50, [&](const diagnostic_msgs::DiagnosticArray::ConstPtr& m) {
        for (const auto& st : m->status)
          if (st.hardware_id == "picker_1") statuses.push_back(st);
      });
  ASSERT_TRUE(waitFor([&] { return !statuses.empty(); }));
  bool has_rejected = false, has_future = false;
  // A status taken after the bad input was processed (however slow the machine), not one from before.
  waitFor([&] {
    has_rejected = has_future = false;
    for (const auto& kv : statuses.back().values) {
      if (kv.key == "rejected (invalid)") has_rejected = std::stoi(kv.value) >= 1;
      if (kv.key == "observations stamped in the future (dropped)") has_future = kv.value == "1";
    }
    return has_rejected && has_future;
  });
  EXPECT_TRUE(has_rejected);
  EXPECT_TRUE(has_future);

  // 8. Reset: the belief is forgotten; the next observation initialises it again.
  ros::ServiceClient reset = nh_.serviceClient<picker_localisation::ResetBelief>("/pickers/picker_1/reset");
  picker_localisation::ResetBelief r;
  ASSERT_TRUE(reset.call(r));
  EXPECT_TRUE(r.response.success);
  picker_localisation::WhatIf empty;
  ASSERT_TRUE(what_if.call(empty));
  EXPECT_FALSE(empty.response.success);
  EXPECT_EQ(empty.response.belief.particle_count, 0u);
  send(observationAt(node_b, "gnss", "picker_1"));
  ASSERT_TRUE(waitFor([&] { return topics_["picker_1"].beliefs.back().observations == 1; }));
  EXPECT_LE(hops(topics_["picker_1"].beliefs.back().estimated_node, node_b), 1);
}

std::vector<std::string> listedIds(ros::NodeHandle& nh) {
  picker_localisation::ListPickers list;
  std::vector<std::string> ids;
  if (!ros::service::call("/tpf_tracker/list_pickers", list)) return {"<list_pickers failed>"};
  for (const auto& p : list.response.pickers) ids.push_back(p.id);
  return ids;
}

TEST_F(TrackerTest, PickersAddedAndRemovedAtRunTime) {
  const std::vector<std::string> initial{"picker_1", "picker_2", "picker_3"};
  ASSERT_TRUE(ros::service::waitForService("/tpf_tracker/add_picker", ros::Duration(30.0)));
  EXPECT_EQ(listedIds(nh_), initial);
  std::vector<picker_localisation::PickerList> lists;
  ros::Subscriber registry = nh_.subscribe<picker_localisation::PickerList>(
      "/pickers/registry", 10, [&](const picker_localisation::PickerList::ConstPtr& m) { lists.push_back(*m); });
  ASSERT_TRUE(waitFor([&] { return !lists.empty(); })) << "/pickers/registry is not latched";
  EXPECT_EQ(lists.back().pickers.size(), 3u);

  // Bad requests: a clear message, nothing changes.
  auto request = [](const std::string& id, std::vector<std::string> rfid = {}, const std::string& gnss = "",
                    const std::string& overrides = "") {
    picker_localisation::AddPicker a;
    a.request.picker.id = id;
    a.request.picker.rfid_tags = std::move(rfid);
    a.request.picker.gnss_topic = gnss;
    a.request.tpf_overrides = overrides;
    return a;
  };
  struct Bad {
    picker_localisation::AddPicker call;
    const char* says;  // a word the refusal must contain
  };
  std::vector<Bad> bad{{request(""), "empty"},
                       {request("9lives"), "letter"},
                       {request("bad-id"), "letters, digits"},
                       {request("picker_1"), "duplicate"},
                       {request("picker_9", {"rfid_0001"}), "rfid_0001"},
                       {request("picker_9", {""}), "empty RFID"},
                       {request("picker_9", {}, "not a topic"), "gnss_topic"},
                       {request("picker_9", {}, "", "{num_particles: 0}"), "num_particles"},
                       {request("picker_9", {}, "", "[1, 2]"), "mapping"}};
  for (auto& b : bad) {
    ASSERT_TRUE(ros::service::call("/tpf_tracker/add_picker", b.call)) << b.call.request.picker.id;
    EXPECT_FALSE(b.call.response.success) << b.call.request.picker.id << " " << b.says;
    EXPECT_NE(b.call.response.message.find(b.says), std::string::npos) << b.call.response.message;
  }
  EXPECT_EQ(listedIds(nh_), initial);
  EXPECT_FALSE(ros::service::exists("/pickers/picker_9/what_if", false));

  // A good one: its own filter (its overrides), topics and services, reached only by its observations.
  auto add = request("picker_4", {"rfid_0004"}, "/pickers/picker_4/fix", "{num_particles: 200}");
  ASSERT_TRUE(ros::service::call("/tpf_tracker/add_picker", add));
  ASSERT_TRUE(add.response.success) << add.response.message;
  EXPECT_EQ(listedIds(nh_), (std::vector<std::string>{"picker_1", "picker_2", "picker_3", "picker_4"}));
  ASSERT_TRUE(waitFor([&] { return lists.back().pickers.size() == 4u; }));
  EXPECT_EQ(lists.back().pickers.back().gnss_topic, "/pickers/picker_4/fix");
  ASSERT_TRUE(ros::service::waitForService("/pickers/picker_4/what_if", ros::Duration(60.0)));
  std::vector<PickerBelief> beliefs4;
  ros::Subscriber sub4 = nh_.subscribe<PickerBelief>(
      "/pickers/picker_4/belief", 20, [&](const PickerBelief::ConstPtr& m) { beliefs4.push_back(*m); });
  ASSERT_TRUE(waitFor([&] { return sub4.getNumPublishers() > 0; }));
  spinFor(0.3);
  const std::string node_b = farNodes(*map_).second;
  const std::uint32_t p1 = topics_["picker_1"].beliefs.empty() ? 0 : topics_["picker_1"].beliefs.back().observations;
  send(observationAt(node_b, "rfid", "picker_4"));
  ASSERT_TRUE(waitFor([&] { return !beliefs4.empty() && beliefs4.back().observations == 1; }));
  EXPECT_EQ(beliefs4.back().particle_count, 200u);
  EXPECT_LE(hops(beliefs4.back().estimated_node, node_b), 1);
  spinFor(0.3);
  if (!topics_["picker_1"].beliefs.empty()) {
    EXPECT_EQ(topics_["picker_1"].beliefs.back().observations, p1);
  }
  // On demand: nobody subscribes to picker_4's estimate, so it is not advertised; its belief (subscribed) is.
  ros::master::V_TopicInfo advertised;
  ASSERT_TRUE(ros::master::getTopics(advertised));
  std::set<std::string> names;
  for (const auto& t : advertised) names.insert(t.name);
  EXPECT_TRUE(names.count("/pickers/picker_4/belief"));
  EXPECT_FALSE(names.count("/pickers/picker_4/estimate"));
  EXPECT_TRUE(names.count("/pickers/beliefs"));  // the fleet stream always

  // Removal: unknown ids refused; the picker's services go, the others stay.
  picker_localisation::RemovePicker unknown;
  unknown.request.id = "picker_9";
  ASSERT_TRUE(ros::service::call("/tpf_tracker/remove_picker", unknown));
  EXPECT_FALSE(unknown.response.success);
  EXPECT_NE(unknown.response.message.find("picker_9"), std::string::npos);
  picker_localisation::RemovePicker remove;
  remove.request.id = "picker_4";
  ASSERT_TRUE(ros::service::call("/tpf_tracker/remove_picker", remove));
  EXPECT_TRUE(remove.response.success) << remove.response.message;
  EXPECT_EQ(listedIds(nh_), initial);
  ASSERT_TRUE(waitFor([&] { return lists.back().pickers.size() == 3u; }));
  EXPECT_FALSE(ros::service::exists("/pickers/picker_4/what_if", false));
  EXPECT_TRUE(ros::service::exists("/pickers/picker_1/what_if", false));
  // Added again, it starts afresh.
  auto again = request("picker_4");
  ASSERT_TRUE(ros::service::call("/tpf_tracker/add_picker", again));
  EXPECT_TRUE(again.response.success) << again.response.message;
  EXPECT_EQ(listedIds(nh_).size(), 4u);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_tpf_tracker");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
