#include "picker_localisation/ros/farm_sim_node.h"

#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <picker_localisation/BearingDetectionArray.h>
#include <picker_localisation/PickerCall.h>
#include <picker_localisation/RfidReading.h>
#include <picker_localisation/UwbRange.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/NavSatFix.h>

#include <cmath>
#include <limits>
#include <thread>

#include "picker_localisation/robot/robot_description.h"
#include "picker_localisation/core/yaml_keys.h"
#include "picker_localisation/ros/map_source.h"
#include "picker_localisation/ros/param_yaml.h"

namespace picker_localisation {
namespace ros_adapter {

namespace {

geometry_msgs::Quaternion yawQuaternion(double yaw) {
  geometry_msgs::Quaternion q;
  q.z = std::sin(0.5 * yaw);
  q.w = std::cos(0.5 * yaw);
  return q;
}

geometry_msgs::TransformStamped planarTransform(const ros::Time& stamp, const std::string& parent,
                                                const std::string& child, const sim::Pose2D& p,
                                                double z = 0.0) {
  geometry_msgs::TransformStamped t;
  t.header.stamp = stamp;
  t.header.frame_id = parent;
  t.child_frame_id = child;
  t.transform.translation.x = p.x;
  t.transform.translation.y = p.y;
  t.transform.translation.z = z;
  t.transform.rotation = yawQuaternion(p.yaw);
  return t;
}

// laser_front -> scan_front; any other frame name f -> scan_f.
std::string scanTopicFor(const std::string& frame) {
  const std::string stem = "laser_";
  return frame.compare(0, stem.size(), stem) == 0 ? "scan_" + frame.substr(stem.size()) : "scan_" + frame;
}

}  // namespace

sim::RobotSensorLayout sensorLayoutFromUrdfTemplate(const std::string& path) {
  const robot::RobotDescription d = robot::RobotDescription::fromTemplateFile(path, "");
  auto mounts = [&](const std::string& stem) {
    std::vector<sim::SensorMount2D> out;
    for (const auto& m : d.mountsStartingWith(stem)) {
      if (m.link.size() >= 8 && m.link.compare(m.link.size() - 8, 8, "_optical") == 0) continue;
      out.push_back({m.link, {m.x(), m.y(), m.yaw()}, m.z()});
    }
    return out;
  };
  sim::RobotSensorLayout layout;
  layout.lasers = mounts("laser_");
  layout.rfid_antennas = mounts("rfid_");
  layout.uwb_anchors = mounts("uwb_anchor_");
  layout.cameras = mounts("camera_");
  if (layout.lasers.empty()) throw std::runtime_error(path + ": no laser_* link in the robot description");
  return layout;
}

namespace {
template <typename T>
void readOptional(const YAML::Node& y, const char* key, std::optional<T>& out) {
  T v{};
  if (!y[key]) return;
  core::readOption(y, "farm_sim", key, v);
  out = v;
}
}  // namespace

const std::vector<std::string>& FarmSimOptions::yamlKeys() {
  static const std::vector<std::string> keys{"sim_config",
                                             "urdf_template",
                                             "pickers_file",
                                             "datum_file",
                                             "datum_source",
                                             "seed",
                                             "robots",
                                             "robot_speed",
                                             "patrol",
                                             "enable_gnss",
                                             "enable_laser",
                                             "enable_rfid",
                                             "enable_uwb",
                                             "enable_camera",
                                             "rate_factor",
                                             "duration",
                                             "clock_step",
                                             "start_time",
                                             "start_delay",
                                             "ground_truth_rate",
                                             "publish_sensor_frames",
                                             "map_frame",
                                             "map_file",
                                             "map_topic",
                                             "map_timeout",
                                             "calls",
                                             "tray_time_mean",
                                             "calls_topic",
                                             "call_status_topic"};
  return keys;
}

FarmSimOptions FarmSimOptions::fromYaml(const YAML::Node& y, std::vector<std::string>* unknown) {
  FarmSimOptions o;
  if (!y || !y.IsMap()) return o;
  const std::string c = "farm_sim";
  core::readOption(y, c, "sim_config", o.sim_config);
  core::readOption(y, c, "urdf_template", o.urdf_template);
  core::readOption(y, c, "pickers_file", o.pickers_file);
  core::readOption(y, c, "datum_file", o.datum_file);
  core::readOption(y, c, "datum_source", o.datum_source);
  readOptional(y, "seed", o.seed);
  readOptional(y, "robots", o.robots);
  readOptional(y, "robot_speed", o.robot_speed);
  readOptional(y, "patrol", o.patrol);
  readOptional(y, "enable_gnss", o.enable_gnss);
  readOptional(y, "enable_laser", o.enable_laser);
  readOptional(y, "enable_rfid", o.enable_rfid);
  readOptional(y, "enable_uwb", o.enable_uwb);
  readOptional(y, "enable_camera", o.enable_camera);
  readOptional(y, "calls", o.calls);
  readOptional(y, "tray_time_mean", o.tray_time_mean);
  core::readOption(y, c, "calls_topic", o.calls_topic);
  core::readOption(y, c, "call_status_topic", o.call_status_topic);
  core::readOption(y, c, "rate_factor", o.rate_factor);
  core::readOption(y, c, "duration", o.duration);
  core::readOption(y, c, "clock_step", o.clock_step);
  core::readOption(y, c, "start_time", o.start_time);
  core::readOption(y, c, "start_delay", o.start_delay);
  core::readOption(y, c, "ground_truth_rate", o.ground_truth_rate);
  core::readOption(y, c, "publish_sensor_frames", o.publish_sensor_frames);
  core::readOption(y, c, "map_frame", o.map_frame);
  return core::checkOptions(o, y, yamlKeys(), c, unknown);
}

std::string FarmSimOptions::validate() const {
  const auto bad = core::badValue;
  if (seed && *seed < 0) return bad("seed", *seed, ">= 0");
  if (robots && *robots < 0) return bad("robots", *robots, ">= 0");
  if (robot_speed && !(*robot_speed > 0.0)) return bad("robot_speed", *robot_speed, "> 0");
  if (tray_time_mean && !(*tray_time_mean > 0.0)) return bad("tray_time_mean", *tray_time_mean, "> 0");
  if (!std::isfinite(rate_factor)) return bad("rate_factor", rate_factor, "finite (<= 0: as fast as possible)");
  if (!(duration >= 0.0)) return bad("duration", duration, ">= 0 (0: forever)");
  if (!(clock_step > 0.0) || !std::isfinite(clock_step)) return bad("clock_step", clock_step, "finite and > 0");
  if (!(start_time > 0.0) || !std::isfinite(start_time)) return bad("start_time", start_time, "finite and > 0");
  if (!(start_delay >= 0.0) || !std::isfinite(start_delay))
    return bad("start_delay", start_delay, "finite and >= 0");
  if (!(ground_truth_rate > 0.0)) return bad("ground_truth_rate", ground_truth_rate, "> 0");
  if (datum_source != "auto" && datum_source != "file" && datum_source != "map")
    return "datum_source = " + datum_source + ": must be auto, file or map";
  return "";
}

void FarmSimOptions::applyOverrides(sim::SimConfig& config) const {
  if (seed) config.seed = static_cast<std::uint64_t>(*seed);
  if (robots) config.num_robots = static_cast<std::size_t>(*robots);
  if (robot_speed) config.robot_motion.speed = *robot_speed;
  if (patrol) config.robot_motion.patrol = sim::parsePatrolPolicy(*patrol);
  if (enable_gnss) config.enable.gnss = *enable_gnss;
  if (enable_laser) config.enable.laser = *enable_laser;
  if (enable_rfid) config.enable.rfid = *enable_rfid;
  if (enable_uwb) config.enable.uwb = *enable_uwb;
  if (enable_camera) config.enable.camera = *enable_camera;
  if (calls) config.calls.enabled = *calls;
  if (tray_time_mean) config.calls.tray_time_mean = *tray_time_mean;
}

FarmSimNode::FarmSimNode(ros::NodeHandle& nh, ros::NodeHandle& pnh) : nh_(nh), pnh_(pnh) {
  // One options schema for the node's parameters; the simulator's from ~sim_config, then the overrides.
  FarmSimOptions o;
  if (!loadOptions(pnh_, o)) return;
  sim::SimConfig config;
  try {
    if (!o.sim_config.empty()) config = sim::loadSimConfig(o.sim_config);
    if (!o.datum_file.empty()) config.datum = core::GeodeticDatum::load(o.datum_file).config();
    if (!o.urdf_template.empty()) config.sensor_layout = sensorLayoutFromUrdfTemplate(o.urdf_template);
    if (!o.pickers_file.empty()) {
      registry_ = core::PickerRegistry::load(o.pickers_file);
      config.pickers = sim::pickerSpecsFromRegistry(registry_);
    }
    o.applyOverrides(config);
  } catch (const std::exception& e) {
    ROS_FATAL("farm_sim: %s", e.what());
    return;
  }
  rate_factor_ = o.rate_factor;
  duration_ = o.duration;
  clock_step_ = o.clock_step;
  start_time_ = o.start_time;
  start_delay_ = o.start_delay;
  truth_rate_ = o.ground_truth_rate;
  publish_sensor_frames_ = o.publish_sensor_frames;
  map_frame_ = o.map_frame;
  const std::string& datum_source = o.datum_source;

  const std::optional<core::CommonNodeOptions> map_source = mapOptionsOf(pnh_);
  if (!map_source) return;
  map_ = obtainMap(nh_, *map_source);
  if (!map_) return;
  try {
    if (useMapDatum(datum_source, *map_)) {  // the rule gnss_ingest follows, so both use one datum
      config.datum = map_->datum()->config();
      ROS_INFO("farm_sim: fixes use the map's datum (%.7f, %.7f)", config.datum.latitude, config.datum.longitude);
    }
  } catch (const std::exception& e) {
    ROS_FATAL("farm_sim: %s", e.what());
    return;
  }
  try {
    sim_ = std::make_unique<sim::FarmSimulator>(*map_, config);
  } catch (const std::exception& e) {
    ROS_FATAL("farm_sim: %s", e.what());
    return;
  }

  clock_pub_ = nh_.advertise<rosgraph_msgs::Clock>("/clock", 10);
  for (std::size_t i = 0; i < sim_->numPickers(); ++i) {
    const std::string& id = sim_->pickerSpec(i).id;
    const core::PickerConfig* pc = registry_.find(id);
    const std::string topic = pc ? pc->gnss_topic : "/pickers/" + id + "/fix";
    fix_pubs_.push_back(topic.empty() ? ros::Publisher() : nh_.advertise<sensor_msgs::NavSatFix>(topic, 20));
    truth_pubs_.push_back(nh_.advertise<geometry_msgs::PoseStamped>("/pickers/" + id + "/ground_truth", 20));
  }
  const auto& layout = sim_->config().sensor_layout;
  for (std::size_t r = 0; r < sim_->numRobots(); ++r) {
    const std::string ns = "/" + sim_->robot(r).id();
    RobotIo io;
    for (const auto& m : layout.lasers)
      io.scans[m.frame] = nh_.advertise<sensor_msgs::LaserScan>(ns + "/" + scanTopicFor(m.frame), 20);
    io.rfid = nh_.advertise<picker_localisation::RfidReading>(ns + "/rfid", 100);
    io.uwb = nh_.advertise<picker_localisation::UwbRange>(ns + "/uwb", 200);
    io.camera = nh_.advertise<picker_localisation::BearingDetectionArray>(ns + "/camera/detections", 20);
    io.truth = nh_.advertise<geometry_msgs::PoseStamped>(ns + "/ground_truth", 20);
    io.goal = nh_.subscribe<picker_localisation::GoalNode>(
        ns + "/goal", 10, [this, r](const picker_localisation::GoalNode::ConstPtr& m) { onGoal(r, m); });
    robots_.push_back(std::move(io));
  }
  waiting_since_.assign(sim_->numPickers(), std::numeric_limits<double>::quiet_NaN());
  if (sim_->config().calls.enabled) {
    if (!o.calls_topic.empty())
      calls_pub_ = nh_.advertise<picker_localisation::PickerCall>(o.calls_topic, 20);
    if (!o.call_status_topic.empty())
      call_status_sub_ = nh_.subscribe(o.call_status_topic, 10, &FarmSimNode::onCallStatus, this);
  }
  diagnostics_.setHardwareID("farm_sim");
  diagnostics_.add("simulation", this, &FarmSimNode::diagnose);
  diagnostics_.input("goals");
  ROS_INFO(
      "farm_sim: map '%s' (%zu nodes, %zu lanes), %zu pickers, %zu robots, seed %llu, rate factor %.1f, "
      "duration %.0f s",
      map_->name().c_str(), map_->numNodes(), sim_->laneLayout().lanes().size(), sim_->numPickers(),
      sim_->numRobots(), static_cast<unsigned long long>(sim_->config().seed), rate_factor_, duration_);
}

void FarmSimNode::publishStaticFrames() {
  if (!publish_sensor_frames_) return;
  std::vector<geometry_msgs::TransformStamped> frames;
  const auto& layout = sim_->config().sensor_layout;
  const ros::Time stamp = toRos(0.0);
  for (std::size_t r = 0; r < sim_->numRobots(); ++r) {
    const std::string p = sim_->robot(r).id() + "/";
    for (const auto* group : {&layout.lasers, &layout.rfid_antennas, &layout.uwb_anchors, &layout.cameras})
      for (const auto& m : *group)
        frames.push_back(planarTransform(stamp, p + "base_link", p + m.frame, m.pose, m.z));
  }
  static_tf_.sendTransform(frames);
}

void FarmSimNode::publishTf(const ros::Time& stamp) {
  std::vector<geometry_msgs::TransformStamped> tfs;
  for (std::size_t r = 0; r < sim_->numRobots(); ++r) {
    const std::string p = sim_->robot(r).id() + "/";
    // Odometry is perfect in the simulator: map -> odom is the identity, odom -> base_link the true pose.
    tfs.push_back(planarTransform(stamp, map_frame_, p + "odom", sim::Pose2D{}));
    tfs.push_back(planarTransform(stamp, p + "odom", p + "base_link", sim_->robotPose(r)));
  }
  tf_.sendTransform(tfs);
}

void FarmSimNode::publishGroundTruth(const ros::Time& stamp) {
  auto poseMsg = [&](const sim::Pose2D& p) {
    geometry_msgs::PoseStamped m;
    m.header.stamp = stamp;
    m.header.frame_id = map_frame_;
    m.pose.position.x = p.x;
    m.pose.position.y = p.y;
    m.pose.orientation = yawQuaternion(p.yaw);
    return m;
  };
  for (std::size_t i = 0; i < sim_->numPickers(); ++i) truth_pubs_[i].publish(poseMsg(sim_->pickerPose(i)));
  for (std::size_t r = 0; r < sim_->numRobots(); ++r) robots_[r].truth.publish(poseMsg(sim_->robotPose(r)));
}

void FarmSimNode::publish(const sim::SimOutputs& out) {
  for (const auto& c : out.calls) {
    picker_localisation::PickerCall m;
    m.header.stamp = toRos(c.stamp);
    m.picker_id = c.picker_id;
    m.row = c.reported_row;
    waiting_since_[c.picker_index] = m.header.stamp.toSec();
    calls_pub_.publish(m);
    ++n_calls_;
  }
  for (const auto& f : out.gnss) {
    if (!fix_pubs_[f.picker_index]) continue;
    sensor_msgs::NavSatFix m;
    m.header.stamp = toRos(f.stamp);
    m.header.frame_id = f.picker_id + "/gnss";
    m.status.status = static_cast<int8_t>(f.status);
    m.status.service = sensor_msgs::NavSatStatus::SERVICE_GPS;
    m.latitude = f.latitude;
    m.longitude = f.longitude;
    m.altitude = f.altitude;
    for (std::size_t k = 0; k < 9; ++k) m.position_covariance[k] = f.position_covariance[k];
    m.position_covariance_type = static_cast<uint8_t>(f.covariance_type);
    fix_pubs_[f.picker_index].publish(m);
    ++n_fix_;
  }
  for (const auto& s : out.scans) {
    sensor_msgs::LaserScan m;
    m.header.stamp = toRos(s.stamp);
    m.header.frame_id = s.frame_id;
    m.angle_min = static_cast<float>(s.angle_min);
    m.angle_max = static_cast<float>(s.angle_max);
    m.angle_increment = static_cast<float>(s.angle_increment);
    m.scan_time = static_cast<float>(s.scan_time);
    m.time_increment = 0.0f;
    m.range_min = static_cast<float>(s.range_min);
    m.range_max = static_cast<float>(s.range_max);
    m.ranges = s.ranges;
    robots_[s.robot_index].scans[s.mount].publish(m);
    ++n_scan_;
  }
  for (const auto& r : out.rfid) {
    picker_localisation::RfidReading m;
    m.header.stamp = toRos(r.stamp);
    m.header.frame_id = r.frame_id;
    m.robot_id = r.robot_id;
    m.tag_id = r.tag_id;
    m.rssi = r.rssi;
    m.has_phase = r.has_phase;
    m.phase = r.phase;
    robots_[r.robot_index].rfid.publish(m);
    ++n_rfid_;
  }
  for (const auto& u : out.uwb) {
    picker_localisation::UwbRange m;
    m.header.stamp = toRos(u.stamp);
    m.header.frame_id = u.frame_id;
    m.robot_id = u.robot_id;
    m.tag_id = u.tag_id;
    m.range = u.range;
    m.variance = u.variance;
    m.has_pdoa = false;
    robots_[u.robot_index].uwb.publish(m);
    ++n_uwb_;
  }
  for (const auto& c : out.camera) {
    picker_localisation::BearingDetectionArray m;
    m.header.stamp = toRos(c.stamp);
    m.header.frame_id = c.robot_id + "/" + c.frame;
    m.robot_id = c.robot_id;
    for (const auto& b : c.boxes) {
      picker_localisation::BearingDetection d;
      d.box.x_offset = static_cast<uint32_t>(b.x_offset);
      d.box.y_offset = static_cast<uint32_t>(b.y_offset);
      d.box.width = static_cast<uint32_t>(b.width);
      d.box.height = static_cast<uint32_t>(b.height);
      d.bearing = b.bearing;
      d.confidence = b.confidence;
      m.detections.push_back(d);
    }
    robots_[c.robot_index].camera.publish(m);
    ++n_camera_;
  }
}

void FarmSimNode::onCallStatus(const picker_localisation::CallStatusArray::ConstPtr& msg) {
  // The trays were loaded (or the call withdrawn): the picker walks on. Only the picker's open call counts
  // (the status keeps its earlier, closed calls too).
  for (const auto& c : msg->calls) {
    if (c.state != "to_storage" && c.state != "done" && c.state != "cancelled") continue;
    for (std::size_t i = 0; i < sim_->numPickers(); ++i)
      if (sim_->pickerSpec(i).id == c.picker_id && sim_->pickerWaiting(i) &&
          std::abs(c.called.toSec() - waiting_since_[i]) < 1e-3) {
        sim_->releasePicker(i);
        waiting_since_[i] = std::numeric_limits<double>::quiet_NaN();
        ++n_released_;
      }
  }
}

void FarmSimNode::onGoal(std::size_t robot, const picker_localisation::GoalNode::ConstPtr& msg) {
  diagnostics_.tick("goals");
  const std::string& id = sim_->robot(robot).id();
  if (!msg->robot_id.empty() && msg->robot_id != id) {
    ++goals_rejected_;
    ROS_WARN_THROTTLE(5.0, "farm_sim: goal on /%s/goal is for robot '%s'; ignored", id.c_str(),
                      msg->robot_id.c_str());
    return;
  }
  std::optional<topology::NodeIndex> node;
  if (msg->node.empty() && !std::isfinite(msg->pose.position.x))
    return;  // "no goal" (a robot handed back
             // by the dispatcher): it stays
  if (!msg->node.empty()) {
    node = map_->index(msg->node);
  } else if (std::isfinite(msg->pose.position.x) && std::isfinite(msg->pose.position.y)) {
    node = map_->nearestNode({msg->pose.position.x, msg->pose.position.y});
  }
  if (!node) {
    ++goals_rejected_;
    ROS_WARN_THROTTLE(5.0, "farm_sim: goal node '%s' for %s is not on the map; ignored", msg->node.c_str(),
                      id.c_str());
    return;
  }
  sim_->setRobotGoal(robot, *node);
  ++goals_accepted_;
}

void FarmSimNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  const double wall = (ros::WallTime::now() - wall_start_).toSec();
  stat.summary(diagnostic_msgs::DiagnosticStatus::OK,
               goals_rejected_ ? "running (some goals rejected)" : "running");
  stat.add("simulated time (s)", sim_->time());
  stat.add("achieved real-time factor", wall > 0 ? sim_->time() / wall : 0.0);
  stat.add("requested real-time factor", rate_factor_);
  stat.add("fixes published", n_fix_);
  stat.add("scans published", n_scan_);
  stat.add("rfid reads published", n_rfid_);
  stat.add("uwb ranges published", n_uwb_);
  stat.add("camera frames published", n_camera_);
  stat.add("goals accepted", goals_accepted_);
  stat.add("calls", n_calls_);
  stat.add("pickers released", n_released_);
  stat.add("goals rejected", goals_rejected_);
}

void FarmSimNode::tick() {
  const double target = sim_->time() + clock_step_;
  const sim::SimOutputs out = sim_->advanceTo(duration_ > 0.0 ? std::min(target, duration_) : target);
  const ros::Time now = toRos(sim_->time());
  rosgraph_msgs::Clock clock;
  clock.clock = now;
  clock_pub_.publish(clock);
  publishTf(now);
  if (sim_->time() - last_truth_ >= 1.0 / truth_rate_ - 1e-9) {
    publishGroundTruth(now);
    last_truth_ = sim_->time();
  }
  publish(out);
  diagnostics_.publish();  // each step: farm_sim drives the clock
}

void FarmSimNode::run() {
  if (!ok()) return;
  // Let subscribers connect before time starts moving (wall time: the clock is ours). The clock is repeated
  // while it waits: nodes on simulated time (rosbag record among them) start only once they have heard it.
  rosgraph_msgs::Clock clock;
  clock.clock = toRos(0.0);
  clock_pub_.publish(clock);
  publishStaticFrames();
  for (const ros::WallTime until = ros::WallTime::now() + ros::WallDuration(start_delay_);
       ros::ok() && ros::WallTime::now() < until;) {
    ros::WallDuration(0.05).sleep();
    clock_pub_.publish(clock);
    ros::spinOnce();
  }
  wall_start_ = ros::WallTime::now();
  while (ros::ok() && (duration_ <= 0.0 || sim_->time() < duration_ - 1e-9)) {
    tick();
    ros::spinOnce();
    if (rate_factor_ > 0.0) {
      const ros::WallTime due = wall_start_ + ros::WallDuration(sim_->time() / rate_factor_);
      const ros::WallTime now = ros::WallTime::now();
      if (due > now) (due - now).sleep();
    }
  }
  ROS_INFO("farm_sim: finished at simulated time %.1f s (%.1f s wall)", sim_->time(),
           (ros::WallTime::now() - wall_start_).toSec());
}

}  // namespace ros_adapter
}  // namespace picker_localisation
