// config/sim.yaml -> SimConfig.
#include "picker_localisation/core/picker_registry.h"
#include "picker_localisation/sim/farm_simulator.h"

#include <yaml-cpp/yaml.h>

#include <functional>
#include <map>
#include <stdexcept>

namespace picker_localisation {
namespace sim {

namespace {

using Setter = std::function<void(const YAML::Node&)>;

template <typename T>
Setter set(T& field) {
  return [&field](const YAML::Node& n) { field = n.as<T>(); };
}

void applySection(const YAML::Node& node, const std::map<std::string, Setter>& keys,
                  const std::string& source, const std::string& section) {
  if (!node.IsMap()) throw std::runtime_error(source + ": '" + section + "' must be a mapping");
  for (const auto& kv : node) {
    const std::string key = kv.first.as<std::string>();
    const auto it = keys.find(key);
    const std::string where = section.empty() ? key : section + "." + key;
    if (it == keys.end()) throw std::runtime_error(source + ": unknown key '" + where + "'");
    try {
      it->second(kv.second);
    } catch (const YAML::Exception& e) {
      throw std::runtime_error(source + ": bad value for '" + where + "' (" + e.what() + ")");
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(source + ": bad value for '" + where + "' (" + e.what() + ")");
    }
  }
}

std::map<std::string, Setter> pickerMotionKeys(SimConfig& c) {
  return {{"speed_mean", set(c.picker_motion.speed_mean)},
          {"speed_std", set(c.picker_motion.speed_std)},
          {"speed_min", set(c.picker_motion.speed_min)},
          {"speed_max", set(c.picker_motion.speed_max)},
          {"p_reverse", set(c.picker_motion.p_reverse)},
          {"t_reverse", set(c.picker_motion.t_reverse)},
          {"reverse_step", set(c.picker_motion.reverse_step)},
          {"dwell_mean", set(c.picker_motion.dwell_mean)},
          {"long_stop_probability", set(c.picker_motion.long_stop_probability)},
          {"long_stop_mean", set(c.picker_motion.long_stop_mean)},
          {"lane_order",
           [&c](const YAML::Node& n) { c.picker_motion.lane_order = parseLaneOrder(n.as<std::string>()); }},
          {"leg_radius", set(c.picker_motion.leg_radius)},
          {"leg_spread", set(c.picker_motion.leg_spread)},
          {"stride_length", set(c.picker_motion.stride_length)},
          {"step_amplitude", set(c.picker_motion.step_amplitude)}};
}

std::map<std::string, Setter> gnssKeys(SimConfig& c) {
  return {{"offset_min", set(c.gnss.offset_min)},
          {"offset_max", set(c.gnss.offset_max)},
          {"white_std", set(c.gnss.white_std)},
          {"drift_std", set(c.gnss.drift_std)},
          {"drift_tau", set(c.gnss.drift_tau)},
          {"blackout_mean_interval", set(c.gnss.blackout_mean_interval)},
          {"blackout_min", set(c.gnss.blackout_min)},
          {"blackout_max", set(c.gnss.blackout_max)},
          {"blackout_emits_no_fix", set(c.gnss.blackout_emits_no_fix)},
          {"redraw_after_blackout", set(c.gnss.redraw_after_blackout)},
          {"rate", set(c.gnss.rate)},
          {"reported_std", set(c.gnss.reported_std)},
          {"antenna_height", set(c.gnss.antenna_height)}};
}

std::map<std::string, Setter> laserKeys(SimConfig& c) {
  return {{"angle_min", set(c.laser.angle_min)},
          {"angle_max", set(c.laser.angle_max)},
          {"angle_increment", set(c.laser.angle_increment)},
          {"range_min", set(c.laser.range_min)},
          {"range_max", set(c.laser.range_max)},
          {"range_noise_std", set(c.laser.range_noise_std)},
          {"rate", set(c.laser.rate)}};
}

std::map<std::string, Setter> rfidKeys(SimConfig& c) {
  return {{"p_max", set(c.rfid.p_max)},
          {"d50", set(c.rfid.d50)},
          {"width", set(c.rfid.width)},
          {"max_range", set(c.rfid.max_range)},
          {"rssi_1m", set(c.rfid.rssi_1m)},
          {"path_loss_exponent", set(c.rfid.path_loss_exponent)},
          {"rssi_std", set(c.rfid.rssi_std)},
          {"wavelength", set(c.rfid.wavelength)},
          {"phase_std", set(c.rfid.phase_std)},
          {"tag_height", set(c.rfid.tag_height)},
          {"rate", set(c.rfid.rate)}};
}

std::map<std::string, Setter> uwbKeys(SimConfig& c) {
  return {{"range_std", set(c.uwb.range_std)},
          {"p_nlos", set(c.uwb.p_nlos)},
          {"nlos_mean", set(c.uwb.nlos_mean)},
          {"p_dropout", set(c.uwb.p_dropout)},
          {"max_range", set(c.uwb.max_range)},
          {"tag_height", set(c.uwb.tag_height)},
          {"rate", set(c.uwb.rate)}};
}

std::map<std::string, Setter> cameraKeys(SimConfig& c) {
  return {{"image_width", set(c.camera.image_width)},
          {"image_height", set(c.camera.image_height)},
          {"hfov", set(c.camera.hfov)},
          {"max_range", set(c.camera.max_range)},
          {"p_miss", set(c.camera.p_miss)},
          {"pixel_std", set(c.camera.pixel_std)},
          {"person_height", set(c.camera.person_height)},
          {"person_width", set(c.camera.person_width)},
          {"rate", set(c.camera.rate)}};
}

}  // namespace

void applySimConfigYaml(const YAML::Node& root_in, SimConfig& c, const std::string& source) {
  YAML::Node root = root_in;
  if (!root || root.IsNull()) return;
  if (root["sim"] && root.size() == 1) root = root["sim"];
  auto section = [&](std::map<std::string, Setter> keys, const std::string& name) {
    return
        [keys = std::move(keys), name, &source](const YAML::Node& n) { applySection(n, keys, source, name); };
  };
  std::map<std::string, Setter> top{
      {"seed", set(c.seed)},
      {"time_step", set(c.time_step)},
      {"robots", set(c.num_robots)},
      {"robot_ids", set(c.robot_ids)},
      {"robot_start_nodes", set(c.robot_start_nodes)},
      {"picker_motion", section(pickerMotionKeys(c), "picker_motion")},
      {"gnss", section(gnssKeys(c), "gnss")},
      {"datum",
       [&c, &source](const YAML::Node& n) {  // config/datum.yaml's keys (core::DatumConfig)
         std::vector<std::string> unknown;
         c.datum = core::DatumConfig::fromYaml(n, source, &unknown);
         if (!unknown.empty()) throw std::runtime_error(unknown.front());
       }},
      {"robot_motion", section({{"speed", set(c.robot_motion.speed)},
                                {"patrol",
                                 [&c](const YAML::Node& n) {
                                   c.robot_motion.patrol = parsePatrolPolicy(n.as<std::string>());
                                 }}},
                               "robot_motion")},
      {"laser", section(laserKeys(c), "laser")},
      {"rfid", section(rfidKeys(c), "rfid")},
      {"uwb", section(uwbKeys(c), "uwb")},
      {"camera", section(cameraKeys(c), "camera")},
      {"clutter", section({{"bed_posts", set(c.clutter.bed_posts)},
                           {"post_spacing", set(c.clutter.post_spacing)},
                           {"post_offset", set(c.clutter.post_offset)},
                           {"post_radius", set(c.clutter.post_radius)},
                           {"merge_distance", set(c.clutter.merge_distance)}},
                          "clutter")},
      {"calls", section({{"enabled", set(c.calls.enabled)},
                         {"tray_time_mean", set(c.calls.tray_time_mean)},
                         {"reported_row_share", set(c.calls.reported_row_share)},
                         {"wrong_row_probability", set(c.calls.wrong_row_probability)}},
                        "calls")},
      {"enable", section({{"gnss", set(c.enable.gnss)},
                          {"laser", set(c.enable.laser)},
                          {"rfid", set(c.enable.rfid)},
                          {"uwb", set(c.enable.uwb)},
                          {"camera", set(c.enable.camera)}},
                         "enable")},
  };
  applySection(root, top, source, "");
  const PickerMotionParams& m = c.picker_motion;
  if (!(m.long_stop_probability >= 0.0 && m.long_stop_probability <= 1.0))
    throw std::runtime_error(source + ": picker_motion.long_stop_probability must be in [0, 1]");
  if (!(m.long_stop_mean > 0.0))
    throw std::runtime_error(source + ": picker_motion.long_stop_mean must be > 0");
  if (!(c.calls.tray_time_mean > 0.0))
    throw std::runtime_error(source + ": calls.tray_time_mean must be > 0");
  for (double p : {c.calls.reported_row_share, c.calls.wrong_row_probability})
    if (!(p >= 0.0 && p <= 1.0))
      throw std::runtime_error(source +
                               ": calls.reported_row_share and wrong_row_probability must be in [0, 1]");
}

SimConfig loadSimConfig(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": cannot read simulator config (" + e.what() + ")");
  }
  SimConfig c;
  applySimConfigYaml(root, c, path);
  return c;
}

std::vector<PickerSpec> pickerSpecsFromRegistry(const core::PickerRegistry& registry) {
  std::vector<PickerSpec> out;
  for (const auto& p : registry.pickers()) {
    PickerSpec s;
    s.id = p.id;
    s.has_gnss = !p.gnss_topic.empty();
    s.rfid_tag = p.rfid_tags.empty() ? "" : p.rfid_tags.front();
    s.uwb_tag = p.uwb_tag;
    out.push_back(s);
  }
  return out;
}

}  // namespace sim
}  // namespace picker_localisation
