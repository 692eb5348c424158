#include "picker_localisation/sensors_ranging/rfid_observation_model.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace picker_localisation {
namespace sensors {

const char* toString(RfidRejection r) {
  switch (r) {
    case RfidRejection::kNone: return "accepted";
    case RfidRejection::kUnknownTag: return "unknown_tag";
    case RfidRejection::kNotFinite: return "not_finite";
    case RfidRejection::kWeakSignal: return "weak_signal";
    case RfidRejection::kOutOfOrder: return "out_of_order";
  }
  return "unknown";
}

RfidObservationModel::RfidObservationModel(core::PickerRegistry registry,
                                           std::shared_ptr<const topology::TopologicalMap> map,
                                           RfidModelOptions options)
    : registry_(std::move(registry)), map_(std::move(map)), options_(options) {
  if (!map_) throw std::invalid_argument("RfidObservationModel: no map");
  if (!(options_.read_range > 0.0)) throw std::invalid_argument("RfidObservationModel: read_range must be > 0");
  options_.p_detect = std::clamp(options_.p_detect, 0.0, 1.0);
}

std::vector<topology::NodeIndex> RfidObservationModel::nodesInReadRegion(const Eigen::Vector3d& pose) const {
  std::vector<topology::NodeIndex> nodes = map_->nodesWithin(pose.head<2>(), options_.read_range);
  if (options_.beam_half_angle < M_PI) {
    nodes.erase(std::remove_if(nodes.begin(), nodes.end(),
                               [&](topology::NodeIndex n) {
                                 const Eigen::Vector2d d = map_->position2d(n) - pose.head<2>();
                                 if (d.norm() < 1e-9) return false;  // the antenna's own node
                                 const double a = std::remainder(std::atan2(d.y(), d.x()) - pose.z(), 2.0 * M_PI);
                                 return std::abs(a) > options_.beam_half_angle;
                               }),
                nodes.end());
  }
  std::sort(nodes.begin(), nodes.end());
  return nodes;
}

RfidResult RfidObservationModel::process(const RfidRead& read) {
  RfidResult result;
  ++counters_.received;
  auto reject = [&](RfidRejection r, const std::string& why, std::size_t& counter) {
    result.rejection = r;
    result.reason = why;
    ++counter;
    return result;
  };
  if (!std::isfinite(read.stamp) || !read.antenna_pose.allFinite())
    return reject(RfidRejection::kNotFinite, "stamp or antenna pose is NaN/Inf", counters_.not_finite);
  const std::optional<std::string> picker = registry_.pickerForRfidTag(read.tag_id);
  if (!picker) return reject(RfidRejection::kUnknownTag, "unknown tag '" + read.tag_id + "'", counters_.unknown_tag);
  if (std::isfinite(read.rssi) && read.rssi < options_.min_rssi) {
    std::ostringstream s;
    s << "RSSI " << read.rssi << " dBm below min_rssi " << options_.min_rssi;
    return reject(RfidRejection::kWeakSignal, s.str(), counters_.weak_signal);
  }
  auto last = antenna_last_stamp_.find(read.antenna_id);
  if (last != antenna_last_stamp_.end() && read.stamp < last->second - options_.out_of_order_tolerance) {
    std::ostringstream s;
    s << "stamp " << read.stamp << " s is older than the antenna's newest read (" << last->second << " s)";
    return reject(RfidRejection::kOutOfOrder, s.str(), counters_.out_of_order);
  }
  // Reading spell of this antenna (for negative information).
  if (last == antenna_last_stamp_.end() || read.stamp - last->second > options_.negative_window)
    antenna_session_start_[read.antenna_id] = read.stamp;
  antenna_last_stamp_[read.antenna_id] = std::max(read.stamp, last == antenna_last_stamp_.end() ? read.stamp : last->second);
  last_read_[{read.antenna_id, *picker}] = read.stamp;
  ++counters_.accepted;

  core::Observation obs;
  obs.stamp = read.stamp;
  obs.sensor = options_.sensor;
  obs.robot_id = read.robot_id;
  obs.picker_id = *picker;
  obs.identifying = true;
  obs.nodes = nodesInReadRegion(read.antenna_pose);
  if (obs.nodes.empty()) obs.nodes.push_back(map_->nearestNode(read.antenna_pose.head<2>()));
  obs.likelihood.assign(obs.nodes.size(), 1.0);
  obs.position = read.antenna_pose.head<2>();
  // Uniform disc of radius R: variance R^2 / 4 per axis.
  obs.position_covariance = Eigen::Matrix2d::Identity() * options_.read_range * options_.read_range / 4.0;
  result.observation = std::move(obs);
  if (options_.negative_information) result.negative = negativeObservations(read, *picker);
  return result;
}

std::vector<core::Observation> RfidObservationModel::negativeObservations(const RfidRead& read,
                                                                          const std::string& read_picker) {
  std::vector<core::Observation> out;
  // The antenna must have been reading for a whole window before absence of a read means anything.
  if (read.stamp - antenna_session_start_[read.antenna_id] < options_.negative_window) return out;
  std::vector<topology::NodeIndex> inside;
  bool inside_computed = false;
  for (const core::PickerConfig& p : registry_.pickers()) {
    if (p.id == read_picker || p.rfid_tags.empty()) continue;
    const std::pair<std::string, std::string> key{read.antenna_id, p.id};
    auto lr = last_read_.find(key);
    if (lr != last_read_.end() && read.stamp - lr->second <= options_.negative_window) continue;
    auto ln = last_negative_.find(key);
    if (ln != last_negative_.end() && read.stamp - ln->second < options_.negative_period) continue;
    if (!inside_computed) {
      inside = nodesInReadRegion(read.antenna_pose);
      inside_computed = true;
    }
    if (inside.empty()) continue;  // nothing to lower
    core::Observation obs;
    obs.stamp = read.stamp;
    obs.sensor = options_.sensor;
    obs.robot_id = read.robot_id;
    obs.picker_id = p.id;
    obs.identifying = true;
    obs.nodes.resize(map_->numNodes());
    obs.likelihood.assign(map_->numNodes(), 1.0);
    for (topology::NodeIndex n = 0; n < map_->numNodes(); ++n) obs.nodes[n] = n;
    const double low = std::max(1.0 - options_.p_detect, 1e-6);
    for (topology::NodeIndex n : inside) obs.likelihood[n] = low;
    last_negative_[key] = read.stamp;
    ++counters_.negative_sent;
    out.push_back(std::move(obs));
  }
  return out;
}

}  // namespace sensors
}  // namespace picker_localisation
