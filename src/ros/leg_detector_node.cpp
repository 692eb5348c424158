#include "picker_localisation/ros/leg_detector_node.h"
#include "picker_localisation/sensors_vision/leg_detector_node_options.h"

#include <pcl/console/print.h>
#include <pcl_conversions/pcl_conversions.h>
#include <picker_localisation/PersonDetectionArray.h>
#include <ros/package.h>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <optional>

#include "picker_localisation/core/observation.h"
#include "picker_localisation/ros/detection_markers.h"
#include "picker_localisation/ros/map_source.h"
#include "picker_localisation/ros/observation_conversions.h"
#include "picker_localisation/ros/param_yaml.h"
#include "picker_localisation/ros/vision_io.h"
#include "picker_localisation/sensors_vision/person_box_detector.h"

namespace picker_localisation {
namespace ros_adapter {

std::string cloudProblem(const sensor_msgs::PointCloud2& c) {
  const std::uint64_t points = static_cast<std::uint64_t>(c.width) * c.height;
  if (c.point_step == 0) return "point_step is 0";
  if (c.row_step < static_cast<std::uint64_t>(c.width) * c.point_step) return "row_step < width x point_step";
  if (static_cast<std::uint64_t>(c.row_step) * c.height > c.data.size())
    return "data holds " + std::to_string(c.data.size()) + " bytes, row_step x height needs " +
           std::to_string(static_cast<std::uint64_t>(c.row_step) * c.height);
  if (points > 10000000) return "more than 10,000,000 points";
  for (const char* axis : {"x", "y", "z"}) {
    const sensor_msgs::PointField* f = nullptr;
    for (const auto& field : c.fields)
      if (field.name == axis) f = &field;
    if (!f) return std::string("no field ") + axis;
    if (f->datatype != sensor_msgs::PointField::FLOAT32)
      return std::string("field ") + axis + " is not FLOAT32";
    if (static_cast<std::uint64_t>(f->offset) + 4u > c.point_step) return std::string("field ") + axis + " lies beyond point_step";
  }
  return "";
}

LegDetectorNode::LegDetectorNode(ros::NodeHandle nh, ros::NodeHandle pnh)
    : nh_(nh), pnh_(pnh), tf_listener_(tf_buffer_), diagnostics_(nh, pnh) {
  // The node's options; the pipeline's (config/vision.yaml) are the struct the offline runner builds.
  vision::LegDetectorNodeOptions o;
  if (!loadOptions(pnh_, o)) return;
  const core::CommonNodeOptions& common = o.common;
  fixed_frame_ = common.map_frame;
  tf_timeout_ = common.tf_timeout;
  robot_id_ = o.robot_id;
  fusion_max_age_ = o.fusion_max_age;
  max_beams_ = o.max_beams;
  // PCL prints its own unthrottled errors for degenerate clouds (VoxelGrid overflow, RANSAC without a model);
  // malformed clouds are reported here instead, once per throttle period.
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  stamp_guard_ = StampGuard(common.max_future_stamp);

  const vision::LegPipelineOptions& options = o.pipeline;
  std::string model = o.model_file;  // config/vision.yaml documents "" as the shipped model
  if (model.empty()) model = ros::package::getPath("picker_localisation") + "/config/leg_classifier.yml";
  try {
    auto classifier = std::make_shared<vision::LegClassifier>();
    classifier->load(model);
    pipeline_ = std::make_unique<vision::LegPipeline>(classifier, options);
  } catch (const std::exception& e) {
    ROS_FATAL("%s: %s", ros::this_node::getName().c_str(), e.what());
    return;
  }

  if (o.publish_observations) {
    map_ = obtainMap(nh_, common);
    if (!map_) return;
    // A map edited at run time: the next people are placed on it (nothing kept names a node).
    map_follower_ =
        std::make_unique<MapFollower>(nh_, common, map_,
                                      [this](std::shared_ptr<const topology::TopologicalMap> m,
                                             const topology::MapChange&) { map_ = std::move(m); });
  }

  for (const auto& t : o.scan_topics)
    subs_.push_back(nh_.subscribe(t, 10, &LegDetectorNode::scanCallback, this));
  const std::string &cloud_topic = o.cloud_topic, &detections_topic = o.detections_topic,
                    &camera_info_topic = o.camera_info_topic;
  if (!cloud_topic.empty()) subs_.push_back(nh_.subscribe(cloud_topic, 2, &LegDetectorNode::cloudCallback, this));
  if (!detections_topic.empty())
    subs_.push_back(nh_.subscribe(detections_topic, 5, &LegDetectorNode::detectionsCallback, this));
  if (!camera_info_topic.empty())
    subs_.push_back(nh_.subscribe(camera_info_topic, 1, &LegDetectorNode::cameraInfoCallback, this));
  const std::string observations_topic = common.observations_topic;
  people_pub_ = nh_.advertise<picker_localisation::PersonDetectionArray>("people", 10);
  people_markers_pub_ = nh_.advertise<visualization_msgs::MarkerArray>("people/markers", 2);
  if (map_) obs_pub_ = nh_.advertise<picker_localisation::Observation>(observations_topic, 50);

  diagnostics_.setHardwareID(robot_id_.empty() ? "leg_detector" : robot_id_);
  diagnostics_.add("leg detector", this, &LegDetectorNode::diagnose);
  diagnostics_.input("scans", 2.0);
  diagnostics_.start(nh_);
  ok_ = true;
  ROS_INFO("%s: %zu scan topic(s), model %s, fixed frame %s%s", ros::this_node::getName().c_str(),
           o.scan_topics.size(), model.c_str(), fixed_frame_.c_str(),
           detections_topic.empty() ? "" : ", camera fusion on");
}

bool LegDetectorNode::lookup(const std::string& target, const std::string& source, const ros::Time& stamp,
                             Eigen::Isometry3d& out) {
  if (target.empty() || source.empty()) {  // tf2 would print a line per lookup of an empty frame
    ++tf_failures_;
    ROS_WARN_THROTTLE(5.0, "%s: input without a frame id dropped", ros::this_node::getName().c_str());
    return false;
  }
  try {
    const auto t = tf_buffer_.lookupTransform(target, source, stamp, ros::Duration(tf_timeout_)).transform;
    out = Eigen::Translation3d(t.translation.x, t.translation.y, t.translation.z) *
          Eigen::Quaterniond(t.rotation.w, t.rotation.x, t.rotation.y, t.rotation.z);
    return true;
  } catch (const std::exception& e) {  // tf2 exceptions, and ros::Duration's range error for absurd stamps
    ++tf_failures_;
    ROS_WARN_THROTTLE(5.0, "%s: no transform %s -> %s at %.3f: %s (input dropped)", ros::this_node::getName().c_str(),
                      source.c_str(), target.c_str(), stamp.toSec(), e.what());
    return false;
  }
}

bool LegDetectorNode::acceptStamp(const ros::Time& stamp, const char* what) {
  if (stamp_guard_.clockJumpedBack()) {
    ROS_WARN("%s: the clock jumped back: cluster tracks and camera state reset", ros::this_node::getName().c_str());
    pipeline_->reset();
    last_detections_.reset();
  }
  if (!stamp_guard_.tooFarInFuture(stamp)) return true;
  ROS_WARN_THROTTLE(5.0, "%s: %s stamped %.3f is more than %.1f s ahead of the clock: dropped",
                    ros::this_node::getName().c_str(), what, stamp.toSec(), stamp_guard_.maxFuture());
  return false;
}

void LegDetectorNode::scanCallback(const sensor_msgs::LaserScan::ConstPtr& msg) {
  diagnostics_.tick("scans");
  ++scans_;
  if (!acceptStamp(msg->header.stamp, "scan")) return;
  if (msg->header.frame_id.empty()) {
    ++tf_failures_;
    ROS_WARN_THROTTLE(5.0, "%s: scan without a frame id dropped", ros::this_node::getName().c_str());
    return;
  }
  if (max_beams_ > 0 && msg->ranges.size() > static_cast<std::size_t>(max_beams_)) {
    ++bad_scans_;
    ROS_WARN_THROTTLE(5.0, "%s: scan of %zu beams dropped (more than ~max_beams %d: a 2D laser has a few thousand)",
                      ros::this_node::getName().c_str(), msg->ranges.size(), max_beams_);
    return;
  }
  last_input_ = msg->header.stamp;
  const auto scan = toScanData(*msg);
  // REP 117: +inf is a beam that saw nothing within range_max, free space the negative information uses; a
  // scan with neither a valid return nor such a beam (all NaN, -inf or out of limits) says nothing.
  const bool sees_free_space =
      std::any_of(scan.ranges.begin(), scan.ranges.end(), [](float r) { return std::isinf(r) && r > 0.0f; });
  if (scan.validCount() == 0 && !sees_free_space) {
    ++empty_scans_;
    ROS_WARN_THROTTLE(5.0, "%s: scan on %s has no valid return and no free beam (ignored)",
                      ros::this_node::getName().c_str(), msg->header.frame_id.c_str());
    return;
  }
  Eigen::Isometry3d tf;
  if (!lookup(fixed_frame_, msg->header.frame_id, msg->header.stamp, tf)) return;
  const std::vector<vision::PersonCandidate> candidates = pipeline_->scanCandidates(scan, tf);
  publishPeople(msg->header.frame_id, msg->header.stamp, candidates);
  if (!map_) return;
  // "Nobody at these nodes" (LegPipeline::negativeObservation), after this scan's people updated the tracks.
  if (auto negative = pipeline_->negativeObservation(msg->header.frame_id, msg->header.stamp.toSec(), scan,
                                                     tf, candidates, *map_, robot_id_)) {
    obs_pub_.publish(toMsg(*negative, *map_, fixed_frame_));
    ++negative_observations_;
  }
}

void LegDetectorNode::cloudCallback(const sensor_msgs::PointCloud2::ConstPtr& msg) {
  diagnostics_.tick("clouds");
  ++clouds_;
  if (!acceptStamp(msg->header.stamp, "cloud")) return;
  // Validate the cloud against its own metadata before reading its data (pcl::fromROSMsg trusts it).
  const std::string problem = cloudProblem(*msg);
  if (!problem.empty()) {
    ++bad_clouds_;
    ROS_WARN_THROTTLE(5.0, "%s: malformed PointCloud2 dropped: %s", ros::this_node::getName().c_str(),
                      problem.c_str());
    return;
  }
  last_input_ = msg->header.stamp;
  Eigen::Isometry3d tf;
  if (!lookup(fixed_frame_, msg->header.frame_id, msg->header.stamp, tf)) return;
  pcl::PointCloud<pcl::PointXYZ> cloud;
  pcl::fromROSMsg(*msg, cloud);
  if (cloud.empty()) {
    ++empty_scans_;
    ROS_WARN_THROTTLE(5.0, "%s: empty point cloud ignored", ros::this_node::getName().c_str());
    return;
  }
  // The fixed frame's z is up: rotate the cloud into its orientation (origin kept at the sensor, so the range
  // gate stays relative to the sensor) before the ground removal, then translate the people.
  const Eigen::Matrix3f rotation = tf.linear().cast<float>();
  for (auto& p : cloud.points) p.getVector3fMap() = rotation * p.getVector3fMap();
  std::vector<vision::PersonCandidate> people;
  for (const auto& p : cloud_detector_.detect(cloud))
    people.push_back({(p.centroid + tf.translation()).head<2>(), p.confidence, "lidar3d", true});
  publishPeople(msg->header.frame_id, msg->header.stamp, std::move(people));
}

void LegDetectorNode::detectionsCallback(const picker_localisation::BearingDetectionArray::ConstPtr& msg) {
  diagnostics_.tick("camera detections");
  ++camera_frames_;
  if (!acceptStamp(msg->header.stamp, "camera detections")) return;
  for (const auto& d : msg->detections)
    if (!std::isfinite(d.bearing) || !std::isfinite(d.confidence)) {
      ++bad_detections_;
      ROS_WARN_THROTTLE(5.0, "%s: camera detections with a non-finite bearing dropped",
                        ros::this_node::getName().c_str());
      return;
    }
  last_detections_ = msg;
}

void LegDetectorNode::cameraInfoCallback(const sensor_msgs::CameraInfo::ConstPtr& msg) { camera_info_ = msg; }

void LegDetectorNode::publishPeople(const std::string& source_frame, const ros::Time& stamp,
                                    const std::vector<vision::PersonCandidate>& people) {
  // The newest camera frame within fusion_max_age, each used once (Algorithm 4 cones).
  std::optional<vision::CameraCones> camera;
  if (last_detections_ && std::abs(secondsBetween(stamp, last_detections_->header.stamp)) <= fusion_max_age_) {
    Eigen::Isometry3d cam;
    if (lookup(last_detections_->header.frame_id, fixed_frame_, last_detections_->header.stamp, cam)) {
      camera.emplace();
      camera->camera_from_fixed = cam;
      for (const auto& d : last_detections_->detections) {
        vision::BearingCone cone{d.bearing, pipeline_->options().cone_half_width, d.confidence};
        if (camera_info_ && camera_info_->K[0] > 0.0 && d.box.width > 0) {
          // Sec. 3.4.2: the box's min and max x columns bound the cone.
          const vision::CameraIntrinsics k{camera_info_->K[0], camera_info_->K[2],
                                            static_cast<int>(camera_info_->width)};
          const double left = vision::bearingFromColumn(d.box.x_offset, k);
          const double right = vision::bearingFromColumn(d.box.x_offset + d.box.width, k);
          cone.half_width = 0.5 * std::abs(left - right);
        }
        camera->cones.push_back(cone);
      }
      last_detections_.reset();
    }
  }
  const std::vector<vision::TrackedPerson> tracked =
      pipeline_->track(source_frame, stamp.toSec(), people, camera ? &*camera : nullptr);

  picker_localisation::PersonDetectionArray out;
  out.header.stamp = stamp;
  out.header.frame_id = fixed_frame_;
  out.robot_id = robot_id_;
  for (const auto& t : tracked) {
    picker_localisation::PersonDetection d;
    d.position.x = t.position.x();
    d.position.y = t.position.y();
    const double var = pipeline_->options().position_sigma * pipeline_->options().position_sigma;
    d.covariance[0] = d.covariance[4] = var;
    d.sensor = t.sensor;
    d.confidence = t.confidence;
    d.track_id = t.track_id;
    fused_ += t.camera_confirmed ? 1 : 0;
    out.detections.push_back(d);
    if (map_) {
      obs_pub_.publish(toMsg(vision::LegPipeline::observation(t, *map_, stamp.toSec(), robot_id_), *map_, fixed_frame_));
      ++observations_;
    }
  }
  people_ += out.detections.size();
  people_pub_.publish(out);
  if (people_markers_pub_.getNumSubscribers() > 0) people_markers_pub_.publish(personMarkers(out));
}

void LegDetectorNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat) {
  if (scans_ + clouds_ == 0)
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "no scan received yet");
  else if (tf_failures_ > 0 && tf_failures_ * 2 > scans_ + clouds_)
    stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "most inputs dropped: missing tf");
  else
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "running");
  stat.add("scans", scans_);
  stat.add("clouds", clouds_);
  stat.add("empty inputs", empty_scans_);
  stat.add("tf failures (dropped)", tf_failures_);
  stat.add("stamps in the future (dropped)", stamp_guard_.futureStamps());
  stat.add("malformed clouds (dropped)", bad_clouds_);
  stat.add("scans over max_beams (dropped)", bad_scans_);
  stat.add("non-finite camera detections (dropped)", bad_detections_);
  stat.add("clock jumps back", stamp_guard_.jumps());
  stat.add("camera frames", camera_frames_);
  stat.add("people published", people_);
  stat.add("camera-confirmed people", fused_);
  stat.add("observations published", observations_);
  stat.add("negative observations published", negative_observations_);
  stat.add("live tracks", pipeline_ ? pipeline_->liveTracks() : 0);
  stat.add("last input stamp", last_input_.toSec());
}

}  // namespace ros_adapter
}  // namespace picker_localisation
