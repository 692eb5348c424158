// Round trip across areas: fixes the simulator produces through config/datum.yaml, turned back into map
// metres by the Ranging engineer's GeodeticDatum (what gnss_ingest does), land on truth + the injected error.
#include <gtest/gtest.h>

#include "picker_localisation/sensors_ranging/geodetic_datum.h"
#include "picker_localisation/sim/gnss_model.h"

using namespace picker_localisation;

TEST(SimDatum, GnssIngestDatumInvertsSimulatedFixes) {
  const std::string path = std::string(PL_PACKAGE_DIR) + "/config/datum.yaml";
  const sim::MapDatum datum = sim::loadMapDatum(path);
  const sim::MapProjection proj(datum);
  const sensors::GeodeticDatum ingest = sensors::GeodeticDatum::load(path);
  sim::GnssNoiseParams params;
  params.blackout_mean_interval = 0.0;
  sim::GnssErrorModel model(params, 3);
  for (int k = 1; k <= 200; ++k) {
    const Eigen::Vector2d truth(12.0 + 0.1 * k, -37.0 + 0.2 * k);
    const auto fix = sim::makeGnssFix(model, proj, params, k, truth);
    ASSERT_TRUE(fix);
    const Eigen::Vector2d back = ingest.toMap(fix->latitude, fix->longitude, fix->altitude);
    EXPECT_NEAR((back - (truth + fix->error)).norm(), 0.0, 1e-3);
  }
  // And with a rotated map frame.
  sim::MapDatum rotated = datum;
  rotated.heading_deg = 37.0;
  sensors::DatumConfig cfg = ingest.config();
  cfg.heading = 37.0 * M_PI / 180.0;
  const sensors::GeodeticDatum ingest_rot(cfg);
  const sim::MapProjection proj_rot(rotated);
  double lat, lon, alt;
  proj_rot.toGeodetic({25.0, -10.0}, 0.0, lat, lon, alt);
  EXPECT_NEAR((ingest_rot.toMap(lat, lon, alt) - Eigen::Vector2d(25.0, -10.0)).norm(), 0.0, 1e-3);
}
