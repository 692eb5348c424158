// rostest of the dispatcher node on the Riseholme map (test/dispatcher.test). The test stands in for the
// trackers (beliefs on /pickers/beliefs), the robots' localisation (tf) and their antennas (/<robot>/rfid):
// two calls go to two robots, never one; a third waits for a free robot; cancel frees a robot; a tag read
// close enough is arrival, a weak one or another robot's is not; loading, storage, done; bad calls (unknown
// picker, NaN / off-map fix, unknown row, malformed CAR JSON) each get one clear error and the node keeps
// serving; the reported row goes to the picker's filter as an observation.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <tf2_ros/transform_broadcaster.h>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/PoseStamped.h>
#include <picker_localisation/CallRobot.h>
#include <picker_localisation/CallStatusArray.h>
#include <picker_localisation/CancelCall.h>
#include <picker_localisation/GetCalls.h>
#include <picker_localisation/GoalNode.h>
#include <picker_localisation/Observation.h>
#include <picker_localisation/PickerBeliefArray.h>
#include <picker_localisation/RfidReading.h>
#include <std_msgs/String.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <mutex>
#include <sstream>

#include "picker_localisation/dispatch/call_dispatcher.h"
#include "picker_localisation/topology/map_io.h"
#include "wait_deadline.h"

using namespace picker_localisation;
using topology::NodeIndex;

namespace {

std::shared_ptr<const topology::TopologicalMap> g_map;
std::mutex g_mutex;
std::map<std::string, Eigen::Vector2d> g_robot_xy;  // where the test says each robot is (tf)
std::map<std::string, picker_localisation::GoalNode> g_call_goals;
std::map<std::string, std::string> g_goal_nodes;
std::vector<picker_localisation::Observation> g_row_observations;
std::map<std::string, std::string> g_diag;
picker_localisation::CallStatusArray g_status;
bool g_shared_robot = false;  // two open calls with one robot in some status message

bool waitFor(const std::function<bool()>& condition, double seconds = test_wait::kDeadline) {
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(seconds);
  while (ros::ok() && ros::WallTime::now() < end) {
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      if (condition()) return true;
    }
    ros::WallDuration(0.05).sleep();
  }
  std::lock_guard<std::mutex> lock(g_mutex);
  return condition();
}

const picker_localisation::CallStatus* openCallOf(const std::string& picker) {
  for (const auto& c : g_status.calls)
    if (c.picker_id == picker && c.state != "done" && c.state != "cancelled") return &c;
  return nullptr;
}

std::string state(std::uint64_t call_id) {
  for (const auto& c : g_status.calls)
    if (c.call_id == call_id) return c.state;
  return "";
}

picker_localisation::PickerBelief belief(const std::string& id, const std::vector<NodeIndex>& nodes) {
  picker_localisation::PickerBelief b;
  b.header.stamp = ros::Time::now();
  b.header.frame_id = "map";
  b.picker_id = id;
  for (NodeIndex n : nodes) {
    b.nodes.push_back(g_map->node(n).name);
    b.masses.push_back(1.0 / static_cast<double>(nodes.size()));
  }
  b.estimated_node = b.nodes.front();
  b.particle_count = 100;
  return b;
}

picker_localisation::CallRobot::Response call(const std::string& picker, const std::string& row = "",
                                              double lat = std::numeric_limits<double>::quiet_NaN(),
                                              double lon = 0.0, bool has_fix = false) {
  picker_localisation::CallRobot srv;
  srv.request.call.picker_id = picker;
  srv.request.call.row = row;
  srv.request.call.has_fix = has_fix;
  srv.request.call.latitude = lat;
  srv.request.call.longitude = lon;
  EXPECT_TRUE(ros::service::call("/dispatcher/call", srv));
  return srv.response;
}

bool cancel(const std::string& picker) {
  picker_localisation::CancelCall srv;
  srv.request.picker_id = picker;
  EXPECT_TRUE(ros::service::call("/dispatcher/cancel", srv));
  return srv.response.success;
}

}  // namespace

TEST(DispatcherNode, AnswersCallsAndRefusesBadOnes) {
  ros::NodeHandle nh, pnh("~");
  std::string map_file;
  ASSERT_TRUE(pnh.getParam("map_file", map_file));
  g_map = std::make_shared<const topology::TopologicalMap>(topology::loadMap(map_file));
  ASSERT_GE(g_map->numLanes(), 4u);
  // picker_1 in the first lane, picker_2 in the last; robot_1 stands in the first lane, robot_2 in the last:
  // each call goes to the robot in the picker's lane.
  const auto lane_1 = g_map->laneNodes(0);
  const auto lane_2 = g_map->laneNodes(static_cast<topology::LaneIndex>(g_map->numLanes() - 1));
  const auto lane_3 = g_map->laneNodes(static_cast<topology::LaneIndex>(g_map->numLanes() / 2));
  const NodeIndex p1 = lane_1[lane_1.size() / 2], p2 = lane_2[lane_2.size() / 2],
                  p3 = lane_3[lane_3.size() / 2];
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    g_robot_xy["robot_1"] = g_map->position2d(lane_1.front());
    g_robot_xy["robot_2"] = g_map->position2d(lane_2.front());
  }

  tf2_ros::TransformBroadcaster tf;
  ros::Timer tf_timer = nh.createTimer(ros::Duration(0.05), [&](const ros::TimerEvent&) {
    std::lock_guard<std::mutex> lock(g_mutex);
    for (const auto& [robot, xy] : g_robot_xy) {
      geometry_msgs::TransformStamped t;
      t.header.stamp = ros::Time::now();
      t.header.frame_id = "map";
      t.child_frame_id = robot + "/base_link";
      t.transform.translation.x = xy.x();
      t.transform.translation.y = xy.y();
      t.transform.rotation.w = 1.0;
      tf.sendTransform(t);
    }
  });
  ros::Publisher beliefs_pub = nh.advertise<picker_localisation::PickerBeliefArray>("/pickers/beliefs", 10);
  ros::Timer belief_timer = nh.createTimer(ros::Duration(0.2), [&](const ros::TimerEvent&) {
    picker_localisation::PickerBeliefArray a;
    a.header.stamp = ros::Time::now();
    a.beliefs = {belief("picker_1", {p1}), belief("picker_2", {p2}), belief("picker_3", {p3})};
    beliefs_pub.publish(a);
  });
  std::vector<ros::Subscriber> subs;
  for (const std::string robot : {"robot_1", "robot_2"}) {
    subs.push_back(nh.subscribe<picker_localisation::GoalNode>(
        "/" + robot + "/call_goal", 10, [robot](const picker_localisation::GoalNode::ConstPtr& m) {
          std::lock_guard<std::mutex> lock(g_mutex);
          g_call_goals[robot] = *m;
        }));
    subs.push_back(nh.subscribe<std_msgs::String>("/" + robot + "/call_goal_node", 10,
                                                  [robot](const std_msgs::String::ConstPtr& m) {
                                                    std::lock_guard<std::mutex> lock(g_mutex);
                                                    g_goal_nodes[robot] = m->data;
                                                  }));
  }
  subs.push_back(nh.subscribe<picker_localisation::CallStatusArray>(
      "/dispatcher/status", 50, [&](const picker_localisation::CallStatusArray::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(g_mutex);
        g_status = *m;
        std::map<std::string, int> serving;
        for (const auto& c : m->calls)
          if (!c.robot_id.empty() && c.state != "done" && c.state != "cancelled" && ++serving[c.robot_id] > 1)
            g_shared_robot = true;
      }));
  subs.push_back(nh.subscribe<picker_localisation::Observation>(
      "/observations", 50, [&](const picker_localisation::Observation::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(g_mutex);
        if (m->sensor == "reported_row") g_row_observations.push_back(*m);
      }));
  subs.push_back(nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 50, [&](const diagnostic_msgs::DiagnosticArray::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(g_mutex);
        for (const auto& s : m->status)
          if (s.name.find("dispatcher: dispatcher") != std::string::npos)
            for (const auto& kv : s.values) g_diag[kv.key] = kv.value;
      }));
  ros::Publisher rfid_1 = nh.advertise<picker_localisation::RfidReading>("/robot_1/rfid", 10);
  ros::Publisher car = nh.advertise<std_msgs::String>("/car/calls", 10);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  ASSERT_TRUE(ros::service::waitForService("/dispatcher/call", ros::Duration(test_wait::kDeadline)));
  ASSERT_TRUE(waitFor([&] { return rfid_1.getNumSubscribers() > 0 && car.getNumSubscribers() > 0; }));

  // An unknown picker: refused, with the reason.
  auto r = call("nobody");
  EXPECT_FALSE(r.success);
  EXPECT_NE(r.message.find("unknown picker"), std::string::npos) << r.message;

  // Two calls, two robots: each to the robot in its lane, the goal in the picker's lane.
  r = call("picker_1");
  ASSERT_TRUE(r.success) << r.message;
  const std::uint64_t call_1 = r.call_id;
  r = call("picker_2");
  ASSERT_TRUE(r.success) << r.message;
  EXPECT_FALSE(call("picker_2").success) << "a second open call of one picker must be refused";
  ASSERT_TRUE(waitFor([&] {
    const auto* a = openCallOf("picker_1");
    const auto* b = openCallOf("picker_2");
    return a && b && a->state == "on_the_way" && b->state == "on_the_way" && g_call_goals.count("robot_1") &&
           g_call_goals.count("robot_2") && g_goal_nodes.count("robot_1");
  })) << "both calls on their way";
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    EXPECT_EQ(openCallOf("picker_1")->robot_id, "robot_1");
    EXPECT_EQ(openCallOf("picker_2")->robot_id, "robot_2");
    EXPECT_EQ(g_call_goals["robot_1"].node, g_map->node(p1).name);
    EXPECT_EQ(g_call_goals["robot_1"].target_picker, "picker_1");
    EXPECT_EQ(g_call_goals["robot_1"].policy, "call");
    EXPECT_EQ(g_goal_nodes["robot_1"], g_map->node(p1).name);
    EXPECT_EQ(g_call_goals["robot_2"].node, g_map->node(p2).name);
  }

  // A third call waits: no robot is free.
  r = call("picker_3");
  ASSERT_TRUE(r.success) << r.message;
  const std::uint64_t call_3 = r.call_id;
  ros::WallDuration(1.5).sleep();
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    ASSERT_NE(openCallOf("picker_3"), nullptr);
    EXPECT_EQ(openCallOf("picker_3")->state, "queued");
    EXPECT_EQ(openCallOf("picker_3")->note, "waiting for a free robot");
  }
  // Cancelling picker_2's call frees robot_2 (an empty goal), which then serves picker_3.
  EXPECT_TRUE(cancel("picker_2"));
  EXPECT_FALSE(cancel("picker_2")) << "no open call left to cancel";
  ASSERT_TRUE(waitFor([&] {
    const auto* c = openCallOf("picker_3");
    return c && c->robot_id == "robot_2" && g_call_goals["robot_2"].node == g_map->node(p3).name;
  })) << "the freed robot serves the queued call";

  // Arrival only from the serving robot's own close sensing: a weak read is not, a strong one is.
  auto read = [&](double rssi) {
    picker_localisation::RfidReading m;
    m.header.stamp = ros::Time::now();
    m.header.frame_id = "robot_1/rfid_front";
    m.robot_id = "robot_1";
    m.tag_id = "rfid_0001";
    m.rssi = rssi;
    rfid_1.publish(m);
  };
  read(-70.0);
  ros::WallDuration(1.0).sleep();
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    EXPECT_EQ(state(call_1), "on_the_way") << "a weak read (-70 dBm, metres away) is not arrival";
  }
  read(-40.0);
  ASSERT_TRUE(waitFor([&] { return state(call_1) == "to_storage"; }))
      << "arrived, loaded (load_time 1 s), on the way to storage";
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    for (const auto& c : g_status.calls)
      if (c.call_id == call_1) {
        EXPECT_GT(c.arrived.toSec(), 0.0);
        EXPECT_GE(c.arrived.toSec(), c.assigned.toSec());
      }
    const std::string storage = dispatch::defaultStorageNode(*g_map);
    EXPECT_EQ(g_call_goals["robot_1"].node, storage) << "full trays go to the storage node";
    EXPECT_TRUE(g_call_goals["robot_1"].target_picker.empty());
    g_robot_xy["robot_1"] = g_map->position2d(*g_map->index(storage));  // the robot drives there
  }
  ASSERT_TRUE(waitFor([&] { return state(call_1) == "done"; })) << "done at the storage node";
  ASSERT_TRUE(waitFor([&] { return g_call_goals["robot_1"].node.empty(); })) << "robot_1 handed back";

  // Bad parts of a call are left out with a note; the call is served.
  r = call("picker_2", "", std::numeric_limits<double>::quiet_NaN(), 0.0, true);
  EXPECT_TRUE(r.success) << r.message;
  EXPECT_NE(r.message.find("not a WGS84 position"), std::string::npos) << r.message;
  EXPECT_TRUE(cancel("picker_2"));
  r = call("picker_2", "", 0.0, 0.0, true);  // the Gulf of Guinea
  EXPECT_TRUE(r.success) << r.message;
  EXPECT_NE(r.message.find("off the map"), std::string::npos) << r.message;
  EXPECT_TRUE(cancel("picker_2"));
  r = call("picker_2", "row_does_not_exist");
  EXPECT_TRUE(r.success) << r.message;
  EXPECT_NE(r.message.find("not a lane of the map"), std::string::npos) << r.message;
  EXPECT_TRUE(cancel("picker_2"));

  // The CAR app: a malformed message is refused (diagnostics count it), the node keeps serving; a good one
  // with a row sends the row to the picker's filter; a CANCEL withdraws it.
  std_msgs::String m;
  m.data = "{\"user\": \"picker_2\", \"lat\": ";
  car.publish(m);
  m.data = "[1, 2, 3]";
  car.publish(m);
  ASSERT_TRUE(waitFor([&] {
    return g_diag.count("calls refused") && std::stoi(g_diag["calls refused"]) >= 5;
  })) << "every refused call counted (unknown picker, repeated call, a cancel of no call, two CAR messages)";
  const std::string row = g_map->laneName(g_map->lane(p3));
  m.data = "{\"user\": \"picker_2\", \"lat\": 53.268, \"long\": -0.524, \"row\": \"" + row +
           "\", \"state\": \"CALLED\", \"accu\": 5}";
  car.publish(m);
  ASSERT_TRUE(waitFor([&] { return openCallOf("picker_2") != nullptr; })) << "a valid CAR call is served";
  ASSERT_TRUE(waitFor([&] { return !g_row_observations.empty(); })) << "the reported row goes to the filter";
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    const auto& o = g_row_observations.back();
    EXPECT_TRUE(o.identifying);
    EXPECT_EQ(o.picker_id, "picker_2");
    ASSERT_EQ(o.nodes.size(), g_map->numNodes()) << "evidence over every node, not a restriction";
    for (std::size_t k = 0; k < o.nodes.size(); ++k) {
      const bool in_row = g_map->lane(*g_map->index(o.nodes[k])) == g_map->lane(p3);
      EXPECT_GT(o.likelihood[k], 0.0);
      if (in_row) {
        EXPECT_DOUBLE_EQ(o.likelihood[k], 1.0);
      } else {
        EXPECT_LT(o.likelihood[k], 1.0);
      }
    }
    EXPECT_EQ(openCallOf("picker_2")->row, row);
  }
  m.data = "{\"user\": \"picker_2\", \"state\": \"CANCEL\"}";
  car.publish(m);
  ASSERT_TRUE(waitFor([&] { return openCallOf("picker_2") == nullptr; })) << "the CAR cancel withdraws it";

  // ~get_calls lists them all; no status ever showed one robot on two open calls.
  picker_localisation::GetCalls all;
  all.request.include_closed = true;
  ASSERT_TRUE(ros::service::call("/dispatcher/get_calls", all));
  EXPECT_GE(all.response.calls.size(), 7u);
  // ~calls_log: the header, then every closed call once, with its final state; no open call yet.
  std::string log_file;
  ASSERT_TRUE(ros::NodeHandle("~").getParam("calls_log", log_file));
  std::ifstream log(log_file);
  std::string line;
  ASSERT_TRUE(std::getline(log, line)) << log_file;
  EXPECT_EQ(line, dispatch::callLogHeader());
  std::map<std::uint64_t, std::string> logged;
  while (std::getline(log, line)) {
    std::stringstream cells(line);
    std::string id, picker, robot, logged_state;
    std::getline(cells, id, ',');
    std::getline(cells, picker, ',');
    std::getline(cells, robot, ',');
    std::getline(cells, logged_state, ',');
    EXPECT_TRUE(logged.emplace(std::stoull(id), logged_state).second) << "call " << id << " logged twice";
  }
  for (const auto& c : all.response.calls) {
    const bool closed = c.state == "done" || c.state == "cancelled";
    ASSERT_EQ(logged.count(c.call_id), closed ? 1u : 0u) << "call " << c.call_id << " " << c.state;
    if (closed) {
      EXPECT_EQ(logged.at(c.call_id), c.state);
    }
  }
  std::remove(log_file.c_str());
  std::lock_guard<std::mutex> lock(g_mutex);
  EXPECT_FALSE(g_shared_robot);
  EXPECT_EQ(state(call_3), "on_the_way");
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_dispatcher_node");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
