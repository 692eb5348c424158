// The simulator's fixes through the package's one datum (core::GeodeticDatum, config/datum.yaml), turned back
// into map metres as gnss_ingest does, land on truth + the injected error; a UTM datum as well, and the fixes
// agree with an independent small-distance approximation on the WGS84 ellipsoid.
#include <gtest/gtest.h>

#include "picker_localisation/core/geodetic_datum.h"
#include "picker_localisation/sim/gnss_model.h"

using namespace picker_localisation;

namespace {

// Round trip of 200 simulated fixes through `datum`.
void expectRoundTrip(const core::GeodeticDatum& datum) {
  sim::GnssNoiseParams params;
  params.blackout_mean_interval = 0.0;
  sim::GnssErrorModel model(params, 3);
  for (int k = 1; k <= 200; ++k) {
    const Eigen::Vector2d truth(12.0 + 0.1 * k, -37.0 + 0.2 * k);
    const auto fix = sim::makeGnssFix(model, datum, params, k, truth);
    ASSERT_TRUE(fix);
    const Eigen::Vector2d back = datum.toMap(fix->latitude, fix->longitude, fix->altitude);
    EXPECT_NEAR((back - (truth + fix->error)).norm(), 0.0, 1e-3);
  }
}

}  // namespace

TEST(SimDatum, GnssIngestDatumInvertsSimulatedFixes) {
  const core::GeodeticDatum shipped =
      core::GeodeticDatum::load(std::string(PL_PACKAGE_DIR) + "/config/datum.yaml");
  expectRoundTrip(shipped);
  // Independent of GeographicLib: 100 m north of the origin is 100 / M degrees of latitude, M the meridian
  // radius of curvature of WGS84 at the origin's latitude.
  const double a = 6378137.0, e2 = 6.69437999014e-3, phi = shipped.config().latitude * M_PI / 180.0;
  const double m = a * (1.0 - e2) / std::pow(1.0 - e2 * std::sin(phi) * std::sin(phi), 1.5);
  const Eigen::Vector2d ll = shipped.toLatLon({0.0, 100.0});
  EXPECT_NEAR((ll.x() - shipped.config().latitude) * M_PI / 180.0 * m, 100.0, 0.01);
  // A rotated map frame and a UTM datum (Riseholme is in zone 30 north).
  core::DatumConfig rotated = shipped.config();
  rotated.heading = 37.0 * M_PI / 180.0;
  expectRoundTrip(core::GeodeticDatum(rotated));
  core::DatumConfig utm;
  utm.kind = core::DatumConfig::Kind::kUtm;
  utm.utm_zone = 30;
  utm.utm_easting = 664000.0;
  utm.utm_northing = 5905000.0;
  expectRoundTrip(core::GeodeticDatum(utm));
}
