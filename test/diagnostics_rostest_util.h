// rostest helper: which nodes of the running graph publish on /diagnostics (diagnostic_updater names each
// status
// "<node name without the leading slash>: <task>").
#pragma once

#include <diagnostic_msgs/DiagnosticArray.h>
#include <ros/master.h>
#include <ros/ros.h>

#include <map>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "wait_deadline.h"

namespace diagnostics_test {

using test_wait::kDeadline;  // a collection returns as soon as every expected node reported

// The statuses of each node (by its graph name, with the leading slash) seen within `wall_timeout` s; returns
// early once every node in `expected` has reported.
inline std::map<std::string, std::map<std::string, diagnostic_msgs::DiagnosticStatus>> collect(
    ros::NodeHandle& nh, const std::set<std::string>& expected, double wall_timeout = kDeadline) {
  std::mutex mutex;
  std::map<std::string, std::map<std::string, diagnostic_msgs::DiagnosticStatus>> seen;
  ros::Subscriber sub = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 100, [&](const diagnostic_msgs::DiagnosticArray::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        for (const auto& st : m->status) {
          const auto colon = st.name.find(": ");
          if (colon == std::string::npos) continue;
          seen["/" + st.name.substr(0, colon)][st.name.substr(colon + 2)] = st;
        }
      });
  ros::AsyncSpinner spinner(1);
  spinner.start();
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(wall_timeout);
  while (ros::WallTime::now() < end) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      bool all = true;
      for (const auto& n : expected) all = all && seen.count(n);
      if (all) break;
    }
    ros::WallDuration(0.1).sleep();
  }
  spinner.stop();
  sub.shutdown();
  std::lock_guard<std::mutex> lock(mutex);
  return seen;
}

// The nodes the master knows, without `excluded` and without this test node.
inline std::set<std::string> graphNodes(const std::set<std::string>& excluded) {
  std::vector<std::string> v;
  ros::master::getNodes(v);
  std::set<std::string> out;
  for (const auto& n : v)
    if (!excluded.count(n) && n != ros::this_node::getName()) out.insert(n);
  return out;
}

}  // namespace diagnostics_test
