#include "picker_localisation/sim/farm_simulator.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <type_traits>
#include <unordered_map>

namespace picker_localisation {
namespace sim {

using topology::NodeIndex;

std::uint64_t deriveSeed(std::uint64_t seed, std::uint64_t stream) {
  // SplitMix64 over seed and stream (two rounds so nearby seeds and streams decorrelate).
  auto mix = [](std::uint64_t z) {
    z += 0x9e3779b97f4a7c15ULL;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  };
  return mix(mix(seed) ^ (stream * 0xd1b54a32d192ed03ULL + 0x8cb92ba72f3d8dd7ULL));
}

namespace {
// Generator streams (see the header): one per process, so processes do not disturb each other.
enum Stream : std::uint64_t {
  kPickerMotion = 1000,
  kGnss = 2000,
  kRobotPatrol = 3000,
  kLaser = 4000,
  kRfid = 5000,
  kUwb = 6000,
  kCamera = 7000,
  kWaypoints = 8000,
  kTrays = 9000,
};
constexpr std::uint64_t kStreamStride = 1ULL << 32;  // streams = base * stride + index
std::uint64_t streamId(Stream s, std::size_t i) {
  return static_cast<std::uint64_t>(s) * kStreamStride + i;
}

void checkRate(double rate, const char* what) {
  if (!(rate > 0.0) || !std::isfinite(rate))
    throw std::invalid_argument(std::string("FarmSimulator: rate of ") + what + " must be > 0");
}
}  // namespace

struct FarmSimulator::SensorStreams {
  std::mt19937_64 laser, rfid, uwb, camera;
};

FarmSimulator::FarmSimulator(const topology::TopologicalMap& map, SimConfig config)
    : map_(&map), config_(std::move(config)), layout_(map), datum_(config_.datum) {
  if (!(config_.time_step > 0.0)) throw std::invalid_argument("FarmSimulator: time_step must be > 0");
  checkRate(config_.gnss.rate, "gnss");
  checkRate(config_.laser.rate, "laser");
  checkRate(config_.rfid.rate, "rfid");
  checkRate(config_.uwb.rate, "uwb");
  checkRate(config_.camera.rate, "camera");
  if (!(config_.laser.angle_increment > 0.0) || config_.laser.angle_max < config_.laser.angle_min)
    throw std::invalid_argument(
        "FarmSimulator: laser angles need angle_increment > 0 and angle_max >= angle_min");
  if (config_.pickers.empty()) {
    for (int i = 1; i <= 3; ++i) {
      PickerSpec p;
      p.id = "picker_" + std::to_string(i);
      p.rfid_tag = "rfid_000" + std::to_string(i);
      p.uwb_tag = "uwb_000" + std::to_string(i);
      config_.pickers.push_back(p);
    }
  }
  const std::uint64_t seed = config_.seed;

  // Pickers: the largest component hosts the tour on maps without lanes.
  std::vector<std::size_t> comp_size(map.numComponents(), 0);
  for (NodeIndex n = 0; n < map.numNodes(); ++n) ++comp_size[static_cast<std::size_t>(map.component(n))];
  const int big = static_cast<int>(std::max_element(comp_size.begin(), comp_size.end()) - comp_size.begin());
  std::vector<NodeIndex> big_nodes;
  for (NodeIndex n = 0; n < map.numNodes(); ++n)
    if (map.component(n) == big) big_nodes.push_back(n);

  const std::size_t n_pickers = config_.pickers.size();
  const std::size_t L = layout_.lanes().size();
  for (std::size_t i = 0; i < n_pickers; ++i) {
    const PickerSpec& spec = config_.pickers[i];
    std::vector<NodeIndex> tour;
    if (L > 0) {
      std::size_t start;
      if (spec.start_lane >= 0) {
        start = static_cast<std::size_t>(spec.start_lane) % L;
      } else {
        start = (i * L) / n_pickers;
        start -= start % 2;  // even positions are walked from the entry end (the paper's left side)
      }
      tour = buildLaneTour(map, layout_, start, {}, config_.picker_motion.lane_order);
    } else {
      std::mt19937_64 wrng(deriveSeed(seed, streamId(kWaypoints, i)));
      std::uniform_int_distribution<std::size_t> pick(0, big_nodes.size() - 1);
      std::vector<NodeIndex> waypoints;
      for (int k = 0; k < 16; ++k) waypoints.push_back(big_nodes[pick(wrng)]);
      tour = buildLaneTour(map, layout_, 0, waypoints);
    }
    pickers_.emplace_back(map, std::move(tour), config_.picker_motion,
                          deriveSeed(seed, streamId(kPickerMotion, i)), 0.0);
    gnss_.emplace_back(config_.gnss, deriveSeed(seed, streamId(kGnss, i)), 0.0);
    tray_rng_.emplace_back(deriveSeed(seed, streamId(kTrays, i)));
    waiting_.push_back(false);
    tray_full_at_.push_back(std::uniform_real_distribution<double>(0.5, 1.5)(tray_rng_.back()) *
                            config_.calls.tray_time_mean);
  }

  // Robots.
  if (config_.robot_ids.empty())
    for (std::size_t r = 0; r < config_.num_robots; ++r)
      config_.robot_ids.push_back("robot_" + std::to_string(r + 1));
  config_.num_robots = config_.robot_ids.size();
  for (std::size_t r = 0; r < config_.num_robots; ++r) {
    NodeIndex start;
    if (r < config_.robot_start_nodes.size() && !config_.robot_start_nodes[r].empty()) {
      const auto idx = map.index(config_.robot_start_nodes[r]);
      if (!idx)
        throw std::invalid_argument("FarmSimulator: unknown robot start node '" +
                                    config_.robot_start_nodes[r] + "'");
      start = *idx;
    } else if (L > 0) {
      // Spread over the lanes, at the far end (opposite to where the pickers enter).
      start = layout_.lanes()[(r * L) / config_.num_robots].far_end();
    } else {
      start = big_nodes[(r * big_nodes.size()) / std::max<std::size_t>(1, config_.num_robots)];
    }
    robots_.emplace_back(map, layout_, config_.robot_ids[r], start, config_.robot_motion,
                         deriveSeed(seed, streamId(kRobotPatrol, r)));
    auto s = std::make_unique<SensorStreams>();
    s->laser.seed(deriveSeed(seed, streamId(kLaser, r)));
    s->rfid.seed(deriveSeed(seed, streamId(kRfid, r)));
    s->uwb.seed(deriveSeed(seed, streamId(kUwb, r)));
    s->camera.seed(deriveSeed(seed, streamId(kCamera, r)));
    streams_.push_back(std::move(s));
  }
  buildPosts();
}

FarmSimulator::~FarmSimulator() = default;

void FarmSimulator::buildPosts() {
  posts_.clear();
  if (!config_.clutter.bed_posts || !(config_.clutter.post_spacing > 0.0)) return;
  const double cell = std::max(config_.clutter.merge_distance, 0.05);
  std::unordered_map<std::int64_t, std::vector<std::size_t>> grid;
  auto key = [&](const Eigen::Vector2d& p, int dx, int dy) {
    const std::int64_t gx = static_cast<std::int64_t>(std::floor(p.x() / cell)) + dx;
    const std::int64_t gy = static_cast<std::int64_t>(std::floor(p.y() / cell)) + dy;
    return gx * 73856093LL ^ gy * 19349663LL;
  };
  auto add = [&](const Eigen::Vector2d& p) {
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy) {
        auto it = grid.find(key(p, dx, dy));
        if (it == grid.end()) continue;
        for (std::size_t j : it->second)
          if ((posts_[j].centre - p).norm() < config_.clutter.merge_distance) return;
      }
    grid[key(p, 0, 0)].push_back(posts_.size());
    posts_.push_back({p, config_.clutter.post_radius});
  };
  // Posts along both sides of every lane polyline, every post_spacing metres (from the entry end).
  for (const auto& lane : layout_.lanes()) {
    if (lane.nodes.size() < 2) continue;
    double carry = 0.0;  // distance along the polyline to the next post
    for (std::size_t k = 0; k + 1 < lane.nodes.size(); ++k) {
      const Eigen::Vector2d a = map_->position2d(lane.nodes[k]), b = map_->position2d(lane.nodes[k + 1]);
      const double len = (b - a).norm();
      if (len < 1e-9) continue;
      const Eigen::Vector2d t = (b - a) / len, n(-t.y(), t.x());
      double s = carry;
      for (; s <= len + 1e-9; s += config_.clutter.post_spacing) {
        add(a + s * t + config_.clutter.post_offset * n);
        add(a + s * t - config_.clutter.post_offset * n);
      }
      carry = s - len;
    }
  }
}

SimOutputs FarmSimulator::step(double dt) {
  if (!(dt >= 0.0) || !std::isfinite(dt))
    throw std::invalid_argument("FarmSimulator::step: dt must be finite and >= 0");
  return advanceTo(time_ + dt);
}

SimOutputs FarmSimulator::advanceTo(double t) {
  if (!(t >= time_) || !std::isfinite(t))
    throw std::invalid_argument("FarmSimulator::advanceTo: time must be finite and not go backwards");
  SimOutputs out;
  while (time_ < t - 1e-12) {
    const double dt = std::min(config_.time_step, t - time_);
    internalStep(dt);
    fireSensors(out);
  }
  time_ = std::max(time_, t);
  return out;
}

void FarmSimulator::internalStep(double dt) {
  for (std::size_t i = 0; i < pickers_.size(); ++i)
    if (!waiting_[i]) pickers_[i].step(dt);  // a picker who called stands where it is
  for (auto& r : robots_) r.step(dt);
  time_ += dt;
}

topology::NodeIndex FarmSimulator::pickerNearestNode(std::size_t i) const {
  return pickers_.at(i).state().nearest_node;
}

topology::LaneIndex FarmSimulator::pickerLane(std::size_t i) const {
  return map_->lane(pickerNearestNode(i));
}

std::optional<std::size_t> FarmSimulator::pickerIndex(const std::string& id) const {
  for (std::size_t i = 0; i < config_.pickers.size(); ++i)
    if (config_.pickers[i].id == id) return i;
  return std::nullopt;
}

std::optional<std::size_t> FarmSimulator::robotIndex(const std::string& id) const {
  for (std::size_t r = 0; r < robots_.size(); ++r)
    if (robots_[r].id() == id) return r;
  return std::nullopt;
}

void FarmSimulator::setRobotGoal(std::size_t r, NodeIndex goal) {
  robots_.at(r).setGoal(goal);
}

LaserScene FarmSimulator::laserScene(std::size_t r) const {
  LaserScene scene;
  scene.circles = posts_;
  for (const auto& p : pickers_)
    for (const auto& c : p.legCentres()) scene.circles.push_back({c, p.legRadius()});
  const double hl = 0.5 * config_.sensor_layout.base_length, hw = 0.5 * config_.sensor_layout.base_width;
  for (std::size_t o = 0; o < robots_.size(); ++o) {
    if (o == r) continue;
    const Pose2D& pose = robots_[o].pose();
    const Eigen::Vector2d c[4] = {pose.transform({hl, hw}), pose.transform({-hl, hw}),
                                  pose.transform({-hl, -hw}), pose.transform({hl, -hw})};
    for (int k = 0; k < 4; ++k) scene.segments.push_back({c[k], c[(k + 1) % 4]});
  }
  return scene;
}

namespace {
// Calls fire(stamp) for every tick k / rate in (.., now] not yet fired.
template <typename F>
void onTicks(std::uint64_t& tick, double rate, double now, F&& fire) {
  while (static_cast<double>(tick + 1) / rate <= now + 1e-9) {
    ++tick;
    fire(static_cast<double>(tick) / rate);
  }
}
double distance3d(const Eigen::Vector2d& a, double za, const Eigen::Vector2d& b, double zb) {
  return std::sqrt((a - b).squaredNorm() + (za - zb) * (za - zb));
}
}  // namespace

void FarmSimulator::releasePicker(std::size_t i) {
  if (!waiting_.at(i)) return;
  waiting_[i] = false;
  tray_full_at_[i] =
      time_ + std::uniform_real_distribution<double>(0.5, 1.5)(tray_rng_[i]) * config_.calls.tray_time_mean;
}

void FarmSimulator::callWhenTraysFull(SimOutputs& out) {
  if (!config_.calls.enabled) return;
  for (std::size_t i = 0; i < pickers_.size(); ++i) {
    if (waiting_[i] || time_ < tray_full_at_[i]) continue;
    waiting_[i] = true;
    PickerCall call;
    call.stamp = time_;
    call.picker_index = i;
    call.picker_id = config_.pickers[i].id;
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const topology::LaneIndex lane = pickerLane(i);
    if (u(tray_rng_[i]) < config_.calls.reported_row_share && lane != topology::kNoLane) {
      topology::LaneIndex reported = lane;
      if (u(tray_rng_[i]) < config_.calls.wrong_row_probability && map_->numLanes() > 1) {
        // A neighbouring lane (by index; lanes of one tunnel are numbered side by side).
        const bool down = lane > 0 && (lane + 1 >= static_cast<topology::LaneIndex>(map_->numLanes()) ||
                                       u(tray_rng_[i]) < 0.5);
        reported = down ? lane - 1 : lane + 1;
      }
      call.reported_row = map_->laneName(reported);
    }
    out.calls.push_back(std::move(call));
  }
}

void FarmSimulator::fireSensors(SimOutputs& out) {
  callWhenTraysFull(out);
  const auto& en = config_.enable;
  const auto& layout = config_.sensor_layout;
  onTicks(gnss_tick_, config_.gnss.rate, time_, [&](double stamp) {
    if (!en.gnss) return;
    for (std::size_t i = 0; i < pickers_.size(); ++i) {
      if (!config_.pickers[i].has_gnss) continue;
      auto fix = makeGnssFix(gnss_[i], datum_, config_.gnss, stamp, pickers_[i].pose().position());
      if (!fix) continue;
      fix->picker_id = config_.pickers[i].id;
      fix->picker_index = i;
      out.gnss.push_back(std::move(*fix));
    }
  });
  onTicks(laser_tick_, config_.laser.rate, time_, [&](double stamp) {
    if (!en.laser) return;
    for (std::size_t r = 0; r < robots_.size(); ++r) {
      const LaserScene scene = laserScene(r);
      for (const auto& m : layout.lasers) {
        LaserScanWithTruth scan =
            castLaser(scene, robots_[r].pose().compose(m.pose), config_.laser, stamp, streams_[r]->laser);
        scan.robot_id = robots_[r].id();
        scan.robot_index = r;
        scan.mount = m.frame;
        scan.frame_id = scan.robot_id + "/" + m.frame;
        out.scans.push_back(std::move(scan));
      }
    }
  });
  // RFID and UWB: one attempt per robot, mount and tagged picker; `simulate` fills the model's fields.
  auto tagSensor = [&](double stamp, const std::vector<SensorMount2D>& mounts,
                       const std::string PickerSpec::*tag, double tag_height,
                       std::mt19937_64 SensorStreams::*stream, auto& readings, auto&& simulate) {
    using Reading = typename std::decay_t<decltype(readings)>::value_type;
    for (std::size_t r = 0; r < robots_.size(); ++r)
      for (const auto& m : mounts) {
        const Eigen::Vector2d a = robots_[r].pose().compose(m.pose).position();
        for (std::size_t i = 0; i < pickers_.size(); ++i) {
          if ((config_.pickers[i].*tag).empty()) continue;
          Reading reading;
          const double d = distance3d(a, m.z, pickers_[i].pose().position(), tag_height);
          if (!simulate(d, (*streams_[r]).*stream, reading)) continue;
          reading.stamp = stamp;
          reading.robot_id = robots_[r].id();
          reading.robot_index = r;
          reading.mount = m.frame;
          reading.frame_id = reading.robot_id + "/" + m.frame;
          reading.tag_id = config_.pickers[i].*tag;
          reading.picker_index = i;
          readings.push_back(std::move(reading));
        }
      }
  };
  onTicks(rfid_tick_, config_.rfid.rate, time_, [&](double stamp) {
    if (!en.rfid) return;
    tagSensor(stamp, layout.rfid_antennas, &PickerSpec::rfid_tag, config_.rfid.tag_height,
              &SensorStreams::rfid, out.rfid,
              [&](double d, std::mt19937_64& rng, RfidReadingWithTruth& read) {
                return simulateRfidRead(config_.rfid, d, rng, read);
              });
  });
  onTicks(uwb_tick_, config_.uwb.rate, time_, [&](double stamp) {
    if (!en.uwb) return;
    tagSensor(stamp, layout.uwb_anchors, &PickerSpec::uwb_tag, config_.uwb.tag_height, &SensorStreams::uwb,
              out.uwb, [&](double d, std::mt19937_64& rng, UwbRangeWithTruth& u) {
                return simulateUwbRange(config_.uwb, d, rng, u);
              });
  });
  onTicks(camera_tick_, config_.camera.rate, time_, [&](double stamp) {
    if (!en.camera) return;
    std::vector<Eigen::Vector2d> positions;
    for (const auto& p : pickers_) positions.push_back(p.pose().position());
    for (std::size_t r = 0; r < robots_.size(); ++r)
      for (const auto& m : layout.cameras) {
        CameraFrame f;
        f.stamp = stamp;
        f.robot_id = robots_[r].id();
        f.robot_index = r;
        f.frame = m.frame;
        f.image_width = config_.camera.image_width;
        f.image_height = config_.camera.image_height;
        f.boxes = simulateCamera(config_.camera, robots_[r].pose().compose(m.pose), m.z, positions,
                                 streams_[r]->camera);
        out.camera.push_back(std::move(f));
      }
  });
}

}  // namespace sim
}  // namespace picker_localisation
