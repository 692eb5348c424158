#include "picker_localisation/core/geodetic_datum.h"

#include <yaml-cpp/yaml.h>
#include <GeographicLib/LocalCartesian.hpp>
#include <GeographicLib/UTMUPS.hpp>

#include "picker_localisation/core/yaml_keys.h"

#include <cmath>
#include <stdexcept>

namespace picker_localisation {
namespace core {

struct GeodeticDatum::Impl {
  GeographicLib::LocalCartesian local;
};

namespace {
Eigen::Matrix2d rotation(double yaw) {
  Eigen::Matrix2d r;
  r << std::cos(yaw), -std::sin(yaw), std::sin(yaw), std::cos(yaw);
  return r;
}
}  // namespace

GeodeticDatum::GeodeticDatum(const DatumConfig& config) : config_(config), impl_(std::make_unique<Impl>()) {
  if (!std::isfinite(config.heading)) throw std::invalid_argument("datum: heading is not finite");
  if (config.kind == DatumConfig::Kind::kLocalCartesian) {
    if (!std::isfinite(config.latitude) || std::abs(config.latitude) > 90.0)
      throw std::invalid_argument("datum: latitude not finite or outside [-90, 90]");
    if (!std::isfinite(config.longitude) || std::abs(config.longitude) > 180.0)
      throw std::invalid_argument("datum: longitude not finite or outside [-180, 180]");
    if (!std::isfinite(config.altitude)) throw std::invalid_argument("datum: altitude is not finite");
    impl_->local.Reset(config.latitude, config.longitude, config.altitude);
  } else {
    if (config.utm_zone < 1 || config.utm_zone > 60)
      throw std::invalid_argument("datum: utm_zone outside 1..60");
    if (!std::isfinite(config.utm_easting) || !std::isfinite(config.utm_northing))
      throw std::invalid_argument("datum: utm_easting / utm_northing not finite");
  }
}

GeodeticDatum::~GeodeticDatum() = default;
GeodeticDatum::GeodeticDatum(const GeodeticDatum& o)
    : config_(o.config_), impl_(std::make_unique<Impl>(*o.impl_)) {}
GeodeticDatum& GeodeticDatum::operator=(const GeodeticDatum& o) {
  if (this != &o) {
    config_ = o.config_;
    impl_ = std::make_unique<Impl>(*o.impl_);
  }
  return *this;
}
GeodeticDatum::GeodeticDatum(GeodeticDatum&&) noexcept = default;
GeodeticDatum& GeodeticDatum::operator=(GeodeticDatum&&) noexcept = default;

const std::vector<std::string>& DatumConfig::yamlKeys() {
  static const std::vector<std::string> keys{"type",      "latitude",    "longitude",
                                             "altitude",  "heading_deg", "utm_zone",
                                             "utm_north", "utm_easting", "utm_northing"};
  return keys;
}

DatumConfig DatumConfig::fromYaml(const YAML::Node& d, const std::string& source,
                                  std::vector<std::string>* unknown) {
  if (!d || !d.IsMap()) throw std::runtime_error(source + ": no 'datum' map");
  if (unknown) {
    const auto u = unknownKeys(d, yamlKeys(), source + ": datum");
    unknown->insert(unknown->end(), u.begin(), u.end());
  }
  DatumConfig c;
  auto num = [&](const char* field, double& v, bool required) {
    if (!d[field]) {
      if (required) throw std::runtime_error(source + ": datum field '" + field + "' is missing");
      return;
    }
    try {
      v = d[field].as<double>();
    } catch (const YAML::Exception&) {
      throw std::runtime_error(source + ": datum field '" + field + "' is not a number");
    }
  };
  const std::string type = d["type"] ? d["type"].as<std::string>() : "local_cartesian";
  double heading_deg = 0.0;
  num("heading_deg", heading_deg, false);
  c.heading = heading_deg * M_PI / 180.0;
  if (type == "local_cartesian") {
    c.kind = DatumConfig::Kind::kLocalCartesian;
    num("latitude", c.latitude, true);
    num("longitude", c.longitude, true);
    num("altitude", c.altitude, false);
  } else if (type == "utm") {
    c.kind = DatumConfig::Kind::kUtm;
    double zone = 0.0;
    num("utm_zone", zone, true);
    c.utm_zone = static_cast<int>(zone);
    c.utm_north = d["utm_north"] ? d["utm_north"].as<bool>() : true;
    num("utm_easting", c.utm_easting, true);
    num("utm_northing", c.utm_northing, true);
    num("altitude", c.altitude, false);
  } else {
    throw std::runtime_error(source + ": datum field 'type' must be local_cartesian or utm, not '" + type +
                             "'");
  }
  try {
    GeodeticDatum{c};  // the ranges
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(source + ": " + e.what());
  }
  return c;
}

GeodeticDatum GeodeticDatum::parse(const std::string& yaml_text, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(source + ": not valid YAML: " + e.what());
  }
  return GeodeticDatum(DatumConfig::fromYaml(root["datum"], source));
}

GeodeticDatum GeodeticDatum::load(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(path + ": cannot read: " + e.what());
  }
  return GeodeticDatum(DatumConfig::fromYaml(root["datum"], path));
}

Eigen::Vector2d GeodeticDatum::toMap(double latitude_deg, double longitude_deg, double altitude) const {
  Eigen::Vector2d en;
  if (config_.kind == DatumConfig::Kind::kLocalCartesian) {
    double x, y, z;
    impl_->local.Forward(latitude_deg, longitude_deg, std::isfinite(altitude) ? altitude : config_.altitude,
                         x, y, z);
    en << x, y;
  } else {
    int zone;
    bool north;
    double e, n;
    GeographicLib::UTMUPS::Forward(latitude_deg, longitude_deg, zone, north, e, n, config_.utm_zone);
    // A fix in the other hemisphere than the datum: shift by the false northing difference.
    if (north != config_.utm_north)
      n += north ? GeographicLib::UTMUPS::UTMShift() : -GeographicLib::UTMUPS::UTMShift();
    en << e - config_.utm_easting, n - config_.utm_northing;
  }
  return enuToMap(en);
}

Eigen::Vector2d GeodeticDatum::toLatLon(const Eigen::Vector2d& map_xy) const {
  double lat, lon, alt;
  toGeodetic(map_xy, 0.0, lat, lon, alt);
  return {lat, lon};
}

void GeodeticDatum::toGeodetic(const Eigen::Vector2d& map_xy, double height, double& lat, double& lon,
                               double& alt) const {
  const Eigen::Vector2d en = mapToEnu(map_xy);
  if (config_.kind == DatumConfig::Kind::kLocalCartesian) {
    impl_->local.Reverse(en.x(), en.y(), height, lat, lon, alt);
  } else {
    GeographicLib::UTMUPS::Reverse(config_.utm_zone, config_.utm_north, en.x() + config_.utm_easting,
                                   en.y() + config_.utm_northing, lat, lon);
    alt = config_.altitude + height;
  }
}

Eigen::Vector2d GeodeticDatum::enuToMap(const Eigen::Vector2d& v_en) const {
  return rotation(-config_.heading) * v_en;
}

Eigen::Matrix2d GeodeticDatum::enuToMap(const Eigen::Matrix2d& c_en) const {
  const Eigen::Matrix2d r = rotation(-config_.heading);
  return r * c_en * r.transpose();
}

Eigen::Vector2d GeodeticDatum::mapToEnu(const Eigen::Vector2d& v_map) const {
  return rotation(config_.heading) * v_map;
}

}  // namespace core
}  // namespace picker_localisation
