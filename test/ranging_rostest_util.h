// Helpers of the sensors_ranging rostests: collect /observations and /diagnostics, wait with a deadline.
#pragma once

#include <diagnostic_msgs/DiagnosticArray.h>
#include <picker_localisation/Observation.h>
#include <ros/ros.h>
#include <sensor_msgs/NavSatFix.h>

#include <Eigen/Core>

#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "picker_localisation/core/geodetic_datum.h"
#include "picker_localisation/ros/ranging_nodes.h"
#include "wait_deadline.h"

namespace ranging_test {

struct Collector {
  std::vector<picker_localisation::Observation> obs;
  std::map<std::string, std::string> diag;  // key -> value of the status named `diag_name`
  std::string diag_name;
  ros::Subscriber obs_sub, diag_sub;

  Collector(ros::NodeHandle& nh, const std::string& diagnostic_name) : diag_name(diagnostic_name) {
    obs_sub = nh.subscribe<picker_localisation::Observation>(
        "/observations", 100, [this](const picker_localisation::Observation::ConstPtr& m) { obs.push_back(*m); });
    diag_sub = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
        "/diagnostics", 10, [this](const diagnostic_msgs::DiagnosticArray::ConstPtr& m) {
          for (const auto& s : m->status)
            if (s.name.find(diag_name) != std::string::npos)
              for (const auto& kv : s.values) diag[kv.key] = kv.value;
        });
  }
};

using test_wait::kDeadline;

// Spins until pred() or `seconds` (wall) have passed; returns pred().
inline bool waitFor(const std::function<bool()>& pred, double seconds = kDeadline) {
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(seconds);
  while (ros::ok() && ros::WallTime::now() < end) {
    ros::spinOnce();
    if (pred()) return true;
    ros::WallDuration(0.01).sleep();
  }
  ros::spinOnce();
  return pred();
}

inline void spinFor(double seconds) {
  waitFor([] { return false; }, seconds);
}

inline std::size_t countFor(const std::vector<picker_localisation::Observation>& obs, const std::string& picker) {
  std::size_t n = 0;
  for (const auto& o : obs) n += o.picker_id == picker;
  return n;
}

// A good NavSatFix at map position p (diagonal covariance 1 m^2 east / north).
inline sensor_msgs::NavSatFix fixAt(const picker_localisation::core::GeodeticDatum& datum, const Eigen::Vector2d& p,
                                    const ros::Time& stamp) {
  return picker_localisation::ros_adapter::navSatFixAt(datum, p, stamp, 1.0);
}

}  // namespace ranging_test
