// Fuzz tests of every parser and front-end a message or a file reaches (no input may kill a node):
// seeded random field values and sizes (NaN, +-Inf, 0, huge, negative, random) through the GNSS ingest, the
// RFID model, UWB ranging, the leg pipeline, LaserScan and PointCloud2 conversion, the Observation message ->
// TPF path, the map message and the map loader (mutated tmap2 text, random bytes). Each target must neither
// crash nor throw anything but its documented error, and whatever it outputs must be valid (observations pass
// validateObservation, beliefs sum to 1). Seeded: a failure reproduces; the iteration is in the message.
#include <gtest/gtest.h>
#include <pcl/console/print.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl_conversions/pcl_conversions.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/PointCloud2.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>

#include "fuzz_util.h"
#include "picker_localisation/core/observation.h"
#include "picker_localisation/core/picker_registry.h"
#include "picker_localisation/ros/leg_detector_node.h"
#include "picker_localisation/ros/map_conversions.h"
#include "picker_localisation/ros/observation_conversions.h"
#include "picker_localisation/ros/vision_io.h"
#include "picker_localisation/sensors_ranging/gnss_ingest.h"
#include "picker_localisation/sensors_ranging/rfid_observation_model.h"
#include "picker_localisation/sensors_ranging/uwb_ranging.h"
#include "picker_localisation/sensors_vision/cloud3d_person_detector.h"
#include "picker_localisation/sensors_vision/leg_pipeline.h"
#include "picker_localisation/topology/map_io.h"
#include "picker_localisation/tpf/topological_particle_filter.h"

using namespace picker_localisation;
using fuzz::Wild;

namespace {

const std::string kPackage = PL_PACKAGE_DIR;

std::shared_ptr<const topology::TopologicalMap> riseholme() {
  static const auto map =
      std::make_shared<const topology::TopologicalMap>(topology::loadMap(kPackage + "/config/maps/riseholme.tmap2"));
  return map;
}

core::PickerRegistry registry() { return core::PickerRegistry::load(kPackage + "/config/pickers.yaml"); }

void expectValid(const core::Observation& o, const topology::TopologicalMap& map, const std::string& where) {
  EXPECT_EQ(core::validateObservation(o, map), "") << where;
  if (o.position) EXPECT_TRUE(o.position->allFinite()) << where;
  EXPECT_TRUE(o.position_covariance.allFinite()) << where;
  if (o.velocity) EXPECT_TRUE(o.velocity->allFinite()) << where;
}

constexpr int kIterations = 3000;

}  // namespace

TEST(Fuzz, GnssIngestTakesAnyFix) {
  const auto map = riseholme();
  const core::GeodeticDatum datum = core::GeodeticDatum::load(kPackage + "/config/datum.yaml");
  sensors::GnssIngest gnss("picker_1", map, datum, sensors::GnssIngestOptions::fromYamlFile(
                                                       kPackage + "/config/gnss_ingest.yaml"));
  const Eigen::Vector2d home = datum.toLatLon(Eigen::Vector2d(20.0, -20.0));
  Wild w(1);
  double t = 100.0;
  std::size_t accepted = 0;
  for (int i = 0; i < kIterations; ++i) {
    core::GnssFix f;
    t += 1.0;
    f.stamp = w.chance(0.9) ? t : w.value(t, 50.0);
    if (f.stamp > t + 10.0) continue;  // the node's StampGuard drops these before the core sees them
    f.latitude = w.chance(0.7) ? home.x() + w.uniform(-2e-5, 2e-5) : w.value(home.x(), 1.0);
    f.longitude = w.chance(0.7) ? home.y() + w.uniform(-2e-5, 2e-5) : w.value(home.y(), 1.0);
    f.altitude = w.value(50.0, 10.0);
    f.status = static_cast<int>(w.index(5)) - 2;
    f.covariance_type = static_cast<int>(w.index(6)) - 1;
    for (double& c : f.position_covariance) c = w.chance(0.6) ? 4.0 : w.value(1.0, 10.0);
    sensors::GnssResult r;
    ASSERT_NO_THROW(r = gnss.process(f)) << "fix " << i;
    if (r.accepted()) {
      ++accepted;
      ASSERT_TRUE(r.observation.has_value());
      expectValid(*r.observation, *map, "fix " + std::to_string(i));
    } else {
      EXPECT_FALSE(r.reason.empty()) << "fix " << i;
    }
  }
  const sensors::GnssCounters& c = gnss.counters();
  EXPECT_EQ(c.accepted, accepted);
  EXPECT_EQ(c.received, c.accepted + c.no_fix + c.not_finite + c.negative_covariance + c.out_of_order +
                            c.impossible_jump + c.off_map);
  EXPECT_GT(accepted, 100u) << "no_fix " << c.no_fix << ", not_finite " << c.not_finite << ", negative_cov "
                            << c.negative_covariance << ", out_of_order " << c.out_of_order << ", jump "
                            << c.impossible_jump << ", off_map " << c.off_map;  // the plausible part gets through
}

TEST(Fuzz, RfidModelTakesAnyRead) {
  const auto map = riseholme();
  sensors::RfidObservationModel rfid(registry(), map, sensors::RfidModelOptions::fromYamlFile(
                                                          kPackage + "/config/rfid_ranging.yaml"));
  Wild w(2);
  double t = 10.0;
  std::size_t accepted = 0;
  for (int i = 0; i < kIterations; ++i) {
    sensors::RfidRead r;
    t += 0.2;
    r.stamp = w.chance(0.9) ? t : w.value(t, 5.0);
    r.robot_id = "robot_1";
    r.frame_id = w.name({"robot_1/rfid_left", "robot_1/rfid_right"});
    r.tag_id = w.name({"rfid_0001", "rfid_0002", "rfid_0003"});
    r.antenna_pose = Eigen::Vector3d(w.value(20.0, 10.0), w.value(-20.0, 10.0), w.value(0.0, 3.0));
    r.rssi = w.value(-60.0, 10.0);
    sensors::RfidResult res;
    ASSERT_NO_THROW(res = rfid.process(r)) << "read " << i;
    if (res.accepted()) {
      ++accepted;
      ASSERT_TRUE(res.observation.has_value());
      expectValid(*res.observation, *map, "read " + std::to_string(i));
      EXPECT_TRUE(std::isfinite(r.rssi));
    }
    for (const core::Observation& n : res.negative) expectValid(n, *map, "negative of read " + std::to_string(i));
  }
  EXPECT_GT(accepted, 100u);
}

TEST(Fuzz, UwbRangingTakesAnyRange) {
  const auto map = riseholme();
  sensors::UwbRanging uwb(registry(), map);
  Wild w(3);
  double t = 10.0;
  std::vector<core::Observation> out;
  for (int i = 0; i < kIterations / 3; ++i) {
    sensors::UwbRangeInput in;
    t += 0.03;
    in.stamp = w.chance(0.95) ? t : w.value(t, 2.0);
    in.robot_id = "robot_1";
    in.tag_id = w.name({"uwb_0001", "uwb_0002"});
    in.frame_id = w.name({"a0", "a1", "a2"});
    in.anchor_in_robot = Eigen::Translation2d(w.uniform(-0.5, 0.5), w.uniform(-0.5, 0.5)) * Eigen::Rotation2Dd(0.0);
    in.range = w.value(3.0, 2.0);
    in.variance = w.value(0.01, 0.05);
    if (w.chance(0.3)) in.pdoa_angle = w.value(0.0, 1.0);
    const Eigen::Isometry2d robot = Eigen::Translation2d(w.chance(0.95) ? 20.0 : w.value(20.0, 5.0), -20.0) *
                                    Eigen::Rotation2Dd(w.uniform(-3.0, 3.0));
    ASSERT_NO_THROW(uwb.addRange(in, robot, &out)) << "range " << i;
    if (w.chance(0.05)) {
      sensors::CameraBearings b;
      b.stamp = w.chance(0.8) ? t : w.value(t, 10.0);
      for (std::size_t k = w.size(2); k > 0; --k)
        b.bearings.push_back({Eigen::Vector2d(0.6, 0.0), w.value(0.0, 1.0), 0.0});
      ASSERT_NO_THROW(uwb.addBearings(b)) << "bearings " << i;
    }
    if (w.chance(0.1)) ASSERT_NO_THROW(uwb.flush(t, &out));
  }
  uwb.flush(std::numeric_limits<double>::infinity(), &out);
  for (std::size_t k = 0; k < out.size(); ++k) expectValid(out[k], *map, "uwb observation " + std::to_string(k));
}

TEST(Fuzz, LegPipelineTakesAnyScan) {
  const auto map = riseholme();
  auto classifier = std::make_shared<vision::LegClassifier>();
  classifier->load(kPackage + "/config/leg_classifier.yml");
  vision::LegPipeline legs(classifier, vision::LegPipelineOptions{});
  Wild w(4);
  for (int i = 0; i < 400; ++i) {
    sensor_msgs::LaserScan msg;
    msg.header.stamp = ros::Time(10.0 + 0.1 * i);
    msg.angle_min = static_cast<float>(w.value(-2.0, 1.0));
    msg.angle_increment = static_cast<float>(w.value(0.006, 0.01));
    msg.angle_max = static_cast<float>(w.value(2.0, 1.0));
    msg.range_min = static_cast<float>(w.value(0.05, 0.1));
    msg.range_max = static_cast<float>(w.value(20.0, 10.0));
    msg.ranges.resize(w.size(700));
    for (float& r : msg.ranges) r = static_cast<float>(w.chance(0.8) ? w.uniform(0.5, 6.0) : w.value(3.0, 3.0));
    msg.intensities.resize(w.size(10));
    core::LaserScan scan;
    ASSERT_NO_THROW(scan = ros_adapter::toScanData(msg)) << "scan " << i;
    const Eigen::Isometry3d tf = Eigen::Translation3d(20.0, -20.0, 0.3) * Eigen::AngleAxisd(w.uniform(-3, 3), Eigen::Vector3d::UnitZ());
    std::vector<vision::TrackedPerson> people;
    ASSERT_NO_THROW(people = legs.processScan(w.chance(0.5) ? "front" : "rear", scan.stamp, scan, tf)) << "scan " << i;
    for (const auto& p : people) {
      const core::Observation o = vision::LegPipeline::observation(p, *map, scan.stamp, "robot_1");
      expectValid(o, *map, "person of scan " + std::to_string(i));
    }
  }
}

TEST(Fuzz, PointCloudCheckGuardsTheConversion) {
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);  // as leg_detector does
  Wild w(5);
  vision::Cloud3dPersonDetector detector;
  std::size_t checked_ok = 0;
  for (int i = 0; i < kIterations; ++i) {
    sensor_msgs::PointCloud2 c;
    c.height = w.chance(0.7) ? 1 : static_cast<std::uint32_t>(w.size(4));
    c.width = w.chance(0.7) ? static_cast<std::uint32_t>(w.size(50)) : static_cast<std::uint32_t>(w.rng());
    c.point_step = w.chance(0.7) ? 12 : static_cast<std::uint32_t>(w.chance(0.5) ? w.size(16) : w.rng());
    c.row_step = w.chance(0.8) ? c.width * c.point_step : static_cast<std::uint32_t>(w.rng());
    const char* names[] = {"x", "y", "z"};
    for (int k = 0; k < 3; ++k) {
      if (w.chance(0.03)) continue;  // a missing field
      sensor_msgs::PointField f;
      f.name = names[k];
      f.offset = w.chance(0.85) ? 4u * k : static_cast<std::uint32_t>(w.chance(0.5) ? w.size(16) : w.rng());
      f.datatype = w.chance(0.85) ? sensor_msgs::PointField::FLOAT32 : static_cast<std::uint8_t>(w.index(9));
      f.count = 1;
      c.fields.push_back(f);
    }
    const std::uint64_t want = static_cast<std::uint64_t>(c.row_step) * c.height;
    c.data.resize(w.chance(0.8) && want < 100000 ? want : w.size(600));
    for (auto& b : c.data) b = static_cast<std::uint8_t>(w.index(256));
    const std::string problem = ros_adapter::cloudProblem(c);
    if (!problem.empty()) continue;
    ++checked_ok;
    // What the check lets through, the node converts and detects on: must not crash or throw.
    pcl::PointCloud<pcl::PointXYZ> cloud;
    ASSERT_NO_THROW(pcl::fromROSMsg(c, cloud)) << "cloud " << i;
    EXPECT_EQ(cloud.size(), static_cast<std::size_t>(c.width) * c.height) << "cloud " << i;
    ASSERT_NO_THROW(detector.detect(cloud)) << "cloud " << i;
  }
  EXPECT_GT(checked_ok, 200u);  // the well-formed clouds are accepted, so the detector was exercised
}

TEST(Fuzz, ObservationMessagesCannotBreakTheFilter) {
  const auto map = riseholme();
  tpf::TopologicalParticleFilter filter(map, tpf::TpfParams::fromYamlFile(kPackage + "/config/tpf.yaml"), 7);
  std::vector<std::string> names;
  for (std::size_t n = 0; n < map->numNodes(); ++n) names.push_back(map->node(n).name);
  Wild w(6);
  double t = 10.0;
  std::size_t fused = 0;
  for (int i = 0; i < kIterations; ++i) {
    picker_localisation::Observation m;
    t += 0.5;
    const double stamp = w.chance(0.9) ? t : w.value(t, 20.0);
    m.header.stamp.fromSec(std::isfinite(stamp) && stamp > 0.0 && stamp < 4e9 ? stamp : 1.0);
    m.header.frame_id = "map";
    m.sensor = w.name({"gnss", "rfid", "uwb", "lidar", "pose", "people"});
    m.identifying = w.chance(0.7);
    m.picker_id = "picker_1";
    for (std::size_t k = w.size(10); k > 0; --k) m.nodes.push_back(w.name(names));
    const std::size_t n_likelihood = w.chance(0.8) ? m.nodes.size() : w.size(10);
    for (std::size_t k = 0; k < n_likelihood; ++k) m.likelihood.push_back(w.chance(0.8) ? w.uniform(0.0, 1.0) : w.value(0.5, 1.0));
    m.has_velocity = w.chance(0.5);
    m.velocity.x = w.value(0.0, 1.0);
    m.velocity.y = w.value(0.0, 1.0);
    m.position.x = w.value(20.0, 5.0);
    m.position.y = w.value(-20.0, 5.0);
    for (double& c : m.position_covariance) c = w.value(1.0, 1.0);
    core::Observation o;
    std::size_t unknown = 0;
    ASSERT_NO_THROW(o = ros_adapter::fromMsg(m, *map, &unknown)) << "message " << i;
    tpf::UpdateResult r;
    ASSERT_NO_THROW(r = filter.update(o)) << "message " << i;
    const tpf::Belief& b = filter.belief();
    if (!b.initialised) continue;
    ++fused;
    double total = 0.0;
    for (double mass : b.masses) {
      ASSERT_TRUE(std::isfinite(mass) && mass >= 0.0) << "message " << i;
      total += mass;
    }
    ASSERT_NEAR(total, 1.0, 1e-6) << "message " << i;
    ASSERT_LT(b.map_node, map->numNodes()) << "message " << i;
    if (w.chance(0.05)) ASSERT_NO_THROW(filter.predictTo(b.stamp + w.value(1.0, 100.0))) << "message " << i;
  }
  EXPECT_GT(fused, 100u);
}

TEST(Fuzz, MapMessagesAreMapsOrMapErrors) {
  const picker_localisation::TopologicalMap good = ros_adapter::toMsg(*riseholme(), "map");
  Wild w(7);
  std::size_t rejected = 0;
  for (int i = 0; i < 500; ++i) {
    picker_localisation::TopologicalMap m = good;
    for (int k = static_cast<int>(w.index(6)); k >= 0; --k) {
      switch (w.index(7)) {
        case 0: if (!m.nodes.empty()) m.nodes[w.index(m.nodes.size())].pose.position.x = w.value(0.0, 1e3); break;
        case 1: if (!m.nodes.empty()) m.nodes[w.index(m.nodes.size())].name = w.name({"", m.nodes[0].name}); break;
        case 2: if (!m.edges.empty()) m.edges[w.index(m.edges.size())].target = static_cast<std::uint32_t>(w.rng()); break;
        case 3: if (!m.edges.empty()) m.edges[w.index(m.edges.size())].length = w.value(1.0, 5.0); break;
        case 4: m.nodes.resize(w.index(m.nodes.size() + 1)); break;
        case 5: m.has_datum = true; m.datum_latitude = w.value(53.0, 100.0); break;
        default: if (!m.nodes.empty()) m.nodes[w.index(m.nodes.size())].pose.orientation.w = w.value(1.0, 1.0); break;
      }
    }
    try {
      const topology::TopologicalMap map = ros_adapter::fromMsg(m);
      for (std::size_t n = 0; n < map.numNodes(); ++n) ASSERT_TRUE(map.node(n).position.allFinite()) << "map " << i;
    } catch (const topology::MapError&) {
      ++rejected;
    } catch (const std::exception& e) {
      FAIL() << "map message " << i << " threw something other than MapError: " << e.what();
    }
  }
  EXPECT_GT(rejected, 50u);
}

TEST(Fuzz, MapTextIsAMapOrOneMapError) {
  std::ifstream in(kPackage + "/config/maps/riseholme.tmap2");
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string original = buffer.str();
  fuzz::Wild w(8);
  std::size_t parsed = 0, rejected = 0;
  for (int i = 0; i < 200; ++i) {
    const std::string text = fuzz::mutantMapText(original, i, w);
    try {
      const topology::TopologicalMap map = topology::parseMap(text, "mutant_" + std::to_string(i));
      ++parsed;
      for (std::size_t n = 0; n < map.numNodes(); ++n) ASSERT_TRUE(map.node(n).position.allFinite()) << "mutant " << i;
    } catch (const topology::MapError& e) {
      ++rejected;
      const std::string message = e.what();
      EXPECT_EQ(message.find('\n'), std::string::npos) << "mutant " << i << ": more than one line";
      EXPECT_LT(message.size(), 1200u) << "mutant " << i;
    } catch (const std::exception& e) {
      FAIL() << "mutant " << i << " threw something other than MapError: " << e.what();
    }
  }
  EXPECT_GT(rejected, 30u);
  EXPECT_GT(parsed, 0u);  // some mutations (inside names, comments) still give maps
}
