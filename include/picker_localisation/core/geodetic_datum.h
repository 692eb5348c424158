// Geodetic datum of the map frame: WGS84 latitude / longitude <-> map metres, with GeographicLib (never a
// hand-written projection). ROS-free. The one datum of the package: gnss_ingest turns fixes into map metres
// with it, the farm simulator turns map metres into fixes with it, both from the same keys.
//
// The datum is the lat/lon (and altitude) of the map origin plus the heading of the map x axis, or a UTM zone
// + the UTM coordinates of the map origin + the heading. Heading convention (both kinds): yaw of the map x
// axis in the local east-north frame, counter-clockwise from east, as REP 103 yaw (0: map x points east, map
// y north; pi/2: map x points north). Map frame = rotate(-heading) * (east, north) relative to the origin.
//
// config/datum.yaml:
//   datum:
//     type: local_cartesian     # local_cartesian (GeographicLib::LocalCartesian at the origin) | utm
//     latitude: 53.268          # deg WGS84, map origin
//     longitude: -0.524         # deg WGS84, map origin
//     altitude: 0.0             # m above the ellipsoid, map origin
//     heading_deg: 0.0          # deg, yaw of the map x axis from east, counter-clockwise
//     # utm only (latitude / longitude are then ignored):
//     utm_zone: 30
//     utm_north: true
//     utm_easting: 0.0          # m, UTM easting of the map origin
//     utm_northing: 0.0         # m, UTM northing of the map origin
// UTM kind: the heading is relative to the UTM grid (the meridian convergence, < 2 deg inside a zone, is
// not corrected: use local_cartesian when that matters).
#pragma once

#include <yaml-cpp/yaml.h>
#include <Eigen/Core>

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace picker_localisation {
namespace core {

struct DatumConfig {
  enum class Kind { kLocalCartesian, kUtm };
  Kind kind = Kind::kLocalCartesian;
  double latitude = 0.0;   // deg
  double longitude = 0.0;  // deg
  double altitude = 0.0;   // m
  double heading = 0.0;    // rad (yaml: heading_deg in degrees)
  int utm_zone = 0;
  bool utm_north = true;
  double utm_easting = 0.0;   // m
  double utm_northing = 0.0;  // m

  // The keys of one `datum:` mapping (above). Throws std::runtime_error naming `source` and the field; a key
  // that is not one of yamlKeys() is appended to *unknown (with the closest known key) when given.
  static DatumConfig fromYaml(const YAML::Node& datum, const std::string& source,
                              std::vector<std::string>* unknown = nullptr);
  static const std::vector<std::string>& yamlKeys();
};

class GeodeticDatum {
 public:
  // Throws std::invalid_argument (one line) on a non-finite or out-of-range value or a bad UTM zone.
  explicit GeodeticDatum(const DatumConfig& config);
  ~GeodeticDatum();
  GeodeticDatum(const GeodeticDatum&);
  GeodeticDatum& operator=(const GeodeticDatum&);
  GeodeticDatum(GeodeticDatum&&) noexcept;
  GeodeticDatum& operator=(GeodeticDatum&&) noexcept;

  // Reads the `datum:` block of a YAML file / text. Throws std::runtime_error naming the file and field.
  static GeodeticDatum load(const std::string& path);
  static GeodeticDatum parse(const std::string& yaml_text, const std::string& source = "<memory>");

  const DatumConfig& config() const { return config_; }

  // WGS84 -> map x, y (m). altitude (m, ellipsoidal) may be NaN: the origin's altitude is used then.
  Eigen::Vector2d toMap(double latitude_deg, double longitude_deg, double altitude = 0.0) const;
  // Map x, y (m) -> WGS84 latitude / longitude (deg) at the origin's altitude (for simulators producing
  // fixes).
  Eigen::Vector2d toLatLon(const Eigen::Vector2d& map_xy) const;
  // Map x, y (m) at `height` m above the origin -> WGS84 latitude, longitude (deg) and ellipsoidal altitude
  // (m).
  void toGeodetic(const Eigen::Vector2d& map_xy, double height, double& latitude_deg, double& longitude_deg,
                  double& altitude) const;
  // A vector / covariance in the local east-north frame -> map frame (rotation by -heading).
  Eigen::Vector2d enuToMap(const Eigen::Vector2d& v_en) const;
  Eigen::Matrix2d enuToMap(const Eigen::Matrix2d& c_en) const;
  Eigen::Vector2d mapToEnu(const Eigen::Vector2d& v_map) const;

 private:
  struct Impl;
  DatumConfig config_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace core
}  // namespace picker_localisation
