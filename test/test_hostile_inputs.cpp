// rostest (test/hostile_inputs.test): tpf_tracker and gnss_ingest on a network shared with strangers. Bad
// service requests (particle counts and rates no farm can afford, thousands of override keys, misspelt keys,
// private or shared GNSS topics, ids of 10,000 characters, unknown pickers, absurd what-if horizons) and bad
// messages (another node's empty picker list, picker poses 1,000 km off the map, a PoseArray of 100,000
// people, NaN people, a person with a negative covariance, beliefs stamped in 2100, observations longer than
// the map) are each refused with a message or one log line; every node stays up, both pickers' beliefs keep
// coming from their fixes, and picker_1's belief stays where its fixes put it.
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <geometry_msgs/PoseArray.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <picker_localisation/AddPicker.h>
#include <picker_localisation/ListPickers.h>
#include <picker_localisation/Observation.h>
#include <picker_localisation/PickerBeliefArray.h>
#include <picker_localisation/PickerList.h>
#include <picker_localisation/RemovePicker.h>
#include <picker_localisation/WhatIf.h>
#include <rosgraph_msgs/Log.h>
#include <sensor_msgs/NavSatFix.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "picker_localisation/core/geodetic_datum.h"
#include "picker_localisation/topology/map_io.h"
#include "ranging_rostest_util.h"

namespace pl = picker_localisation;
using ranging_test::spinFor;
using ranging_test::waitFor;

namespace {

class HostileInputs : public ::testing::Test {
 protected:
  void SetUp() override {
    datum_ = std::make_unique<pl::core::GeodeticDatum>(
        pl::core::GeodeticDatum::load(std::string(PL_PACKAGE_DIR) + "/config/datum.yaml"));
    map_ = std::make_unique<pl::topology::TopologicalMap>(
        pl::topology::loadMap(std::string(PL_PACKAGE_DIR) + "/config/maps/riseholme.tmap2"));
    for (const std::string id : {"picker_1", "picker_2"})
      fix_pubs_[id] = nh_.advertise<sensor_msgs::NavSatFix>("/pickers/" + id + "/fix", 10);
    pose_pub_ = nh_.advertise<geometry_msgs::PoseWithCovarianceStamped>("/pickers/picker_1/pose", 10);
    people_pub_ = nh_.advertise<geometry_msgs::PoseArray>("/people_tracker/pose_array", 2);
    person_pub_ = nh_.advertise<pl::Observation>("/person_observations", 10);
    obs_pub_ = nh_.advertise<pl::Observation>("/observations", 10);
    fleet_pub_ = nh_.advertise<pl::PickerBeliefArray>("/pickers/beliefs", 10);
    obs_sub_ =
        nh_.subscribe<pl::Observation>("/observations", 1000, [this](const pl::Observation::ConstPtr& m) {
          if (m->header.stamp.toSec() > 0.0 && m->robot_id != "hostile") observations_.push_back(*m);
        });
    fleet_sub_ = nh_.subscribe<pl::PickerBeliefArray>(
        "/pickers/beliefs", 100, [this](const pl::PickerBeliefArray::ConstPtr& m) {
          for (const auto& b : m->beliefs)
            if (b.header.stamp.toSec() < 4e9) latest_[b.picker_id] = b;  // not our own 2100 belief
        });
    rosout_sub_ = nh_.subscribe<rosgraph_msgs::Log>(
        "/rosout", 1000, [this](const rosgraph_msgs::Log::ConstPtr& m) { log_.push_back(*m); });
    ASSERT_TRUE(ros::service::waitForService("/tpf_tracker/add_picker", ros::Duration(60.0)));
    // Our own subscriptions count on our own publishers: the nodes' links are the second ones.
    ASSERT_TRUE(waitFor([&] {
      return fix_pubs_["picker_1"].getNumSubscribers() > 0 && fix_pubs_["picker_2"].getNumSubscribers() > 0 &&
             pose_pub_.getNumSubscribers() > 0 && people_pub_.getNumSubscribers() > 0 &&
             person_pub_.getNumSubscribers() > 0 && fleet_pub_.getNumSubscribers() >= 2 &&
             obs_pub_.getNumSubscribers() >= 2 && fleet_sub_.getNumPublishers() >= 2 &&
             rosout_sub_.getNumPublishers() >= 2;
    }));
  }

  // Fixes of both pickers at their spots until each picker's belief has counted another observation.
  bool beliefsKeepComing() {
    std::map<std::string, std::uint32_t> before;
    for (const auto& [id, pub] : fix_pubs_) before[id] = latest_.count(id) ? latest_[id].observations : 0;
    return waitFor([&] {
      for (auto& [id, pub] : fix_pubs_) {
        const ros::Time now = ros::Time::now();
        if (now > last_fix_[id] + ros::Duration(0.2)) {
          pub.publish(ranging_test::fixAt(*datum_, spot(id), now));
          last_fix_[id] = now;
        }
      }
      for (const auto& [id, n] : before)
        if (!latest_.count(id) || latest_[id].observations <= n) return false;
      return true;
    });
  }
  Eigen::Vector2d spot(const std::string& id) const {
    return id == "picker_1" ? Eigen::Vector2d(20.0, -20.0) : Eigen::Vector2d(25.0, -30.0);
  }
  // A log line of `node` (WARN or worse) holding `text`, after the first `from` lines.
  bool logged(const std::string& node, const std::string& text, std::size_t from = 0) {
    return waitFor([&] {
      for (std::size_t k = from; k < log_.size(); ++k)
        if (log_[k].name == node && log_[k].level >= rosgraph_msgs::Log::WARN &&
            log_[k].msg.find(text) != std::string::npos)
          return true;
      return false;
    });
  }
  std::size_t observationsOf(const std::string& sensor, std::size_t from) const {
    std::size_t n = 0;
    for (std::size_t k = from; k < observations_.size(); ++k) n += observations_[k].sensor == sensor;
    return n;
  }
  pl::AddPicker addRequest(const std::string& id, const std::string& gnss, const std::string& overrides) {
    pl::AddPicker a;
    a.request.picker.id = id;
    a.request.picker.gnss_topic = gnss;
    a.request.tpf_overrides = overrides;
    return a;
  }
  std::vector<std::string> listed() {
    pl::ListPickers l;
    EXPECT_TRUE(ros::service::call("/tpf_tracker/list_pickers", l));
    std::vector<std::string> ids;
    for (const auto& p : l.response.pickers) ids.push_back(p.id);
    return ids;
  }
  geometry_msgs::PoseWithCovarianceStamped poseAt(const Eigen::Vector2d& at) {
    geometry_msgs::PoseWithCovarianceStamped p;
    p.header.stamp = ros::Time::now();
    p.header.frame_id = "map";
    p.pose.pose.position.x = at.x();
    p.pose.pose.position.y = at.y();
    p.pose.pose.orientation.w = 1.0;
    p.pose.covariance[0] = p.pose.covariance[7] = 1.0;
    return p;
  }

  ros::NodeHandle nh_;
  std::unique_ptr<pl::core::GeodeticDatum> datum_;
  std::unique_ptr<pl::topology::TopologicalMap> map_;
  std::map<std::string, ros::Publisher> fix_pubs_;
  std::map<std::string, ros::Time> last_fix_;
  ros::Publisher pose_pub_, people_pub_, person_pub_, obs_pub_, fleet_pub_;
  ros::Subscriber obs_sub_, fleet_sub_, rosout_sub_;
  std::vector<pl::Observation> observations_;
  std::map<std::string, pl::PickerBelief> latest_;
  std::vector<rosgraph_msgs::Log> log_;
};

TEST_F(HostileInputs, EveryNodeStaysUpAndBeliefsKeepComing) {
  ASSERT_TRUE(beliefsKeepComing()) << "no beliefs from fixes at the start";

  // Other nodes' empty picker lists (the stranger's, latched since the start, and this node's): ignored, each
  // publisher named in one line; GNSS keeps flowing.
  ros::Publisher list_pub = nh_.advertise<pl::PickerList>("/pickers/registry", 1, /*latch=*/true);
  list_pub.publish(pl::PickerList());
  EXPECT_TRUE(logged("/gnss_ingest", "picker list from /hostile_inputs ignored"));
  EXPECT_TRUE(beliefsKeepComing()) << "a stranger's empty list stopped GNSS";

  // add_picker requests no farm can afford or that would half-add a picker: refused, nothing changes.
  auto keys = [](int n) {  // an overrides mapping of n made-up keys
    std::string text = "{";
    for (int k = 0; k < n; ++k) text += (k ? ", k" : "k") + std::to_string(k) + ": 1";
    return text + "}";
  };
  struct Bad {
    pl::AddPicker call;
    const char* says;
  };
  std::vector<Bad> bad{
      {addRequest("picker_7", "", "{num_particles: 2000000000}"), "num_particles"},
      {addRequest("picker_7", "", "{num_particles: 10000000}"), "num_particles"},
      {addRequest("picker_7", "", "{prediction_rate: 1.0e6}"), "prediction_rate"},
      {addRequest("picker_7", "", "{lane_change_max_hops: 100000}"), "lane_change_max_hops"},
      {addRequest("picker_7", "", keys(20000)), "characters"},  // 200 kB: refused before it is parsed
      {addRequest("picker_7", "", keys(1000)), "keys"},
      {addRequest("picker_7", "", "{a: '" + std::string(100000, 'x') + "'}"), "characters"},
      {addRequest("picker_7", "~fix", ""), "private"},
      {addRequest("picker_7", "/pickers/picker_1/fix", ""), "belongs to both"},
      {addRequest("p" + std::string(10000, 'x'), "", ""), "longer than"}};
  for (auto& b : bad) {
    ASSERT_TRUE(ros::service::call("/tpf_tracker/add_picker", b.call)) << b.says;
    EXPECT_FALSE(b.call.response.success) << b.says;
    EXPECT_NE(b.call.response.message.find(b.says), std::string::npos)
        << b.call.response.message.substr(0, 300);
    EXPECT_LT(b.call.response.message.size(), 400u) << "the reply quotes the whole request";
  }
  EXPECT_EQ(listed(), (std::vector<std::string>{"picker_1", "picker_2", "picker_3"}));
  EXPECT_TRUE(beliefsKeepComing()) << "after the refused requests";

  // A misspelt override is named, with the key meant, as at start-up; the picker is tracked.
  pl::AddPicker typo = addRequest("picker_7", "", "{num_particle: 50}");
  ASSERT_TRUE(ros::service::call("/tpf_tracker/add_picker", typo));
  EXPECT_TRUE(typo.response.success) << typo.response.message;
  EXPECT_NE(typo.response.message.find("did you mean 'num_particles'"), std::string::npos)
      << typo.response.message;
  pl::RemovePicker remove;
  remove.request.id = "picker_7";
  ASSERT_TRUE(ros::service::call("/tpf_tracker/remove_picker", remove));
  EXPECT_TRUE(remove.response.success) << remove.response.message;

  // remove_picker of nobody: refused and logged.
  std::size_t mark = log_.size();
  pl::RemovePicker nobody;
  nobody.request.id = "picker_99";
  ASSERT_TRUE(ros::service::call("/tpf_tracker/remove_picker", nobody));
  EXPECT_FALSE(nobody.response.success);
  EXPECT_TRUE(logged("/tpf_tracker", "remove_picker refused", mark));

  // what_if 1e300 s ahead: a clear refusal, not a time-range exception.
  pl::WhatIf what_if;
  what_if.request.horizon = 1e300;
  ASSERT_TRUE(ros::service::call("/pickers/picker_1/what_if", what_if));
  EXPECT_FALSE(what_if.response.success);
  EXPECT_NE(what_if.response.message.find("horizon"), std::string::npos) << what_if.response.message;

  // A picker pose 1,000 km off the map: dropped with a line, never snapped to the map's edge; one on the map
  // still becomes an observation.
  mark = log_.size();
  std::size_t seen = observations_.size();
  pose_pub_.publish(poseAt(Eigen::Vector2d(1.0e6, 0.0)));
  EXPECT_TRUE(logged("/gnss_ingest", "pose of picker_1 dropped", mark));
  spinFor(0.3);
  EXPECT_EQ(observationsOf("pose", seen), 0u);
  pose_pub_.publish(poseAt(spot("picker_1")));
  EXPECT_TRUE(waitFor([&] { return observationsOf("pose", seen) == 1; }));

  // One PoseArray of 100,000 people: refused whole; NaN and off-map people are named and dropped.
  mark = log_.size();
  seen = observations_.size();
  geometry_msgs::PoseArray crowd;
  crowd.header.stamp = ros::Time::now();
  crowd.header.frame_id = "map";
  crowd.poses.resize(100000);
  for (std::size_t k = 0; k < crowd.poses.size(); ++k) crowd.poses[k].position.x = 10.0 + 1e-4 * k;
  people_pub_.publish(crowd);
  EXPECT_TRUE(logged("/gnss_ingest", "100000 people in one message", mark));
  geometry_msgs::PoseArray odd;
  odd.header.stamp = ros::Time::now();
  odd.header.frame_id = "map";
  odd.poses.resize(2);
  odd.poses[0].position.x = std::nan("");
  odd.poses[1].position.x = 1.0e6;
  people_pub_.publish(odd);
  EXPECT_TRUE(logged("/gnss_ingest", "2 of 2 people", mark));
  spinFor(0.3);
  EXPECT_EQ(observationsOf("people", seen), 0u);

  // A person with a negative covariance: dropped with the reason, not forwarded.
  pl::Observation person;
  person.header.stamp = ros::Time::now();
  person.header.frame_id = "map";
  person.sensor = "lidar";
  person.robot_id = "hostile";
  person.nodes = {map_->node(0).name};
  person.likelihood = {1.0};
  person.position.x = map_->node(0).position.x();
  person.position.y = map_->node(0).position.y();
  person.position_covariance[0] = -4.0;
  person.position_covariance[4] = 1.0;
  person_pub_.publish(person);
  EXPECT_TRUE(logged("/gnss_ingest", "position covariance is not positive semi-definite", mark));

  // A belief of picker_1 stamped in 2100 on the fleet stream: dropped (it would hide every later belief).
  pl::PickerBeliefArray future;
  pl::PickerBelief b;
  b.header.stamp = ros::Time(4102444800.0);
  b.picker_id = "picker_1";
  b.nodes = {map_->node(0).name};
  b.masses = {1.0};
  future.beliefs.push_back(b);
  fleet_pub_.publish(future);
  EXPECT_TRUE(logged("/gnss_ingest", "belief of picker_1 dropped", mark));

  // An observation listing more nodes than the map has: dropped by the tracker with a line.
  pl::Observation longer;
  longer.header.stamp = ros::Time::now();
  longer.sensor = "lidar";
  longer.robot_id = "hostile";
  for (std::size_t k = 0; k < 2 * map_->numNodes(); ++k) {
    longer.nodes.push_back(map_->node(k % map_->numNodes()).name);
    longer.likelihood.push_back(1.0);
  }
  obs_pub_.publish(longer);
  EXPECT_TRUE(logged("/tpf_tracker", "nodes dropped: the map has", mark));

  // Every node is up and both pickers are still tracked from their fixes, picker_1 where its fixes are.
  std::vector<std::string> nodes;
  ASSERT_TRUE(ros::master::getNodes(nodes));
  for (const char* n : {"/tpf_tracker", "/gnss_ingest"})
    EXPECT_NE(std::find(nodes.begin(), nodes.end(), n), nodes.end()) << n << " is gone";
  ASSERT_TRUE(beliefsKeepComing()) << "beliefs stopped after the bad inputs";
  const auto estimated = map_->index(latest_["picker_1"].estimated_node);
  ASSERT_TRUE(estimated.has_value()) << latest_["picker_1"].estimated_node;
  EXPECT_LT((map_->position2d(*estimated) - spot("picker_1")).norm(), 10.0)
      << "picker_1's belief moved to " << latest_["picker_1"].estimated_node;
  EXPECT_EQ(listed(), (std::vector<std::string>{"picker_1", "picker_2", "picker_3"}));
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_hostile_inputs");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
