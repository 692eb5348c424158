// sensors::GnssFleet, gnss_ingest's fleet logic shared with the offline runner: the association reads each
// picker's corrected fix and its tracker's belief association_belief_lag before a detection, identifying
// observations of the sighting sensors correct the bias, and a clock jump or a new map forgets what belongs
// to the old time or map.
#include <gtest/gtest.h>

#include <vector>

#include "picker_localisation/core/geodetic_datum.h"
#include "picker_localisation/sensors_ranging/gnss_fleet.h"
#include "ranging_test_maps.h"

using namespace picker_localisation;
using namespace picker_localisation::sensors;
using topology::NodeIndex;

namespace {

core::DatumConfig datumConfig() {
  core::DatumConfig c;
  c.latitude = 53.268;
  c.longitude = -0.524;
  return c;
}

// Three pickers in neighbouring lanes 1.5 m apart (y = 0, 1.5, 3), each with a fix at its true position.
struct ThreeLanes {
  std::shared_ptr<const topology::TopologicalMap> map = ranging_test::latticeMap(20.0, 1.0);
  core::GeodeticDatum datum{datumConfig()};
  GnssFleet fleet;
  explicit ThreeLanes(GnssIngestOptions options = {}) : fleet(map, datum, options) {
    for (const char* id : {"picker_1", "picker_2", "picker_3"}) EXPECT_NE(fleet.add(id), nullptr);
  }
  core::GnssFix fixAt(double t, const Eigen::Vector2d& p) const {
    core::GnssFix f;
    f.stamp = t;
    const Eigen::Vector2d ll = datum.toLatLon(p);
    f.latitude = ll.x();
    f.longitude = ll.y();
    f.position_covariance = {9.0, 0, 0, 0, 9.0, 0, 0, 0, 36.0};
    f.covariance_type = 2;
    return f;
  }
  void fixes(double t) {
    const double y[] = {0.0, 1.5, 3.0};
    for (std::size_t i = 0; i < 3; ++i)
      ASSERT_TRUE(fleet.processFix(*fleet.pickers()[i], fixAt(t, {0.0, y[i]})).accepted());
  }
  core::Observation seen(double t, const Eigen::Vector2d& p, const std::string& sensor = "lidar",
                         const std::string& picker = "") const {
    core::Observation o;
    o.stamp = t;
    o.sensor = sensor;
    o.identifying = !picker.empty();
    o.picker_id = picker;
    o.position = p;
    o.position_covariance = Eigen::Matrix2d::Identity() * 0.09;
    core::setGaussianLikelihood(o, *map, p, o.position_covariance);
    return o;
  }
};

}  // namespace

TEST(GnssFleet, TheLaggedBeliefBreaksATieTheFixesCannot) {
  ThreeLanes f;
  f.fixes(1.0);
  f.fixes(3.0);
  // Side by side, biases unknown: nobody may be named.
  AssociationResult a = f.fleet.associate(f.seen(3.1, {0.0, 3.0}));
  EXPECT_EQ(a.picker, -1);
  EXPECT_EQ(a.observation.candidate_pickers.size(), 3u);
  // Picker 3's tracker is sure where it is. Its belief stamped 2.0 is not used for a detection at 3.1
  // (association_belief_lag 2 s: in the graph it would not have arrived yet); for one at 4.1 it is.
  const std::vector<NodeIndex> sure = {f.map->nearestNode(Eigen::Vector2d(0.0, 3.0))};
  EXPECT_TRUE(f.fleet.addBelief("picker_3", 2.0, sure, {2.0}));  // masses normalised here
  std::vector<NodeIndex> spread;                                 // pickers 1 and 2: anywhere within 10 m
  for (int x = -10; x <= 10; ++x)
    for (int y = -5; y <= 5; ++y) spread.push_back(f.map->nearestNode(Eigen::Vector2d(x, y)));
  for (const char* id : {"picker_1", "picker_2"})
    EXPECT_TRUE(f.fleet.addBelief(id, 2.0, spread, std::vector<double>(spread.size(), 1.0)));
  EXPECT_EQ(f.fleet.associate(f.seen(3.1, {0.0, 3.0})).picker, -1);
  f.fixes(4.0);
  a = f.fleet.associate(f.seen(4.1, {0.0, 3.0}));
  EXPECT_EQ(a.picker, 2);
  EXPECT_EQ(a.observation.picker_id, "picker_3");
  EXPECT_TRUE(a.bias.accepted) << a.bias.reason;
  EXPECT_TRUE(f.fleet.find("picker_3")->ingest.bias().sighted());
  EXPECT_EQ(f.fleet.counters().people, 3u);
  EXPECT_EQ(f.fleet.counters().identified, 1u);
  EXPECT_EQ(f.fleet.counters().sightings, 1u);
  // Beliefs of pickers without GNSS here, or without a usable mass, are not kept.
  EXPECT_FALSE(f.fleet.addBelief("picker_9", 1.0, sure, {1.0}));
  EXPECT_FALSE(f.fleet.addBelief("picker_1", 1.0, sure, {0.0}));
  EXPECT_FALSE(f.fleet.addBelief("picker_1", 1.0, sure, {1.0, 1.0}));
}

TEST(GnssFleet, IdentifyingObservationsOfSightingSensorsCorrectTheBias) {
  GnssIngestOptions o;
  o.bias.sighting_sensors = {"uwb"};
  ThreeLanes f(o);
  f.fixes(1.0);
  EXPECT_TRUE(f.fleet.wantsIdentified(true, "uwb"));
  EXPECT_FALSE(f.fleet.wantsIdentified(false, "uwb"));  // anonymous: the association's business
  EXPECT_FALSE(f.fleet.wantsIdentified(true, "gnss"));  // its own fixes come back on the stream
  EXPECT_FALSE(f.fleet.useIdentified(f.seen(1.1, {0.0, 1.0}, "gnss", "picker_2")));
  EXPECT_FALSE(f.fleet.find("picker_2")->ingest.bias().sighted());
  EXPECT_TRUE(f.fleet.useIdentified(f.seen(1.1, {0.0, 1.0}, "uwb", "picker_2")));
  EXPECT_TRUE(f.fleet.find("picker_2")->ingest.bias().sighted());
  EXPECT_FALSE(f.fleet.find("picker_1")->ingest.bias().sighted());
  EXPECT_FALSE(f.fleet.useIdentified(f.seen(1.1, {0.0, 1.0}, "uwb", "picker_9")));  // no GNSS here
  EXPECT_EQ(f.fleet.counters().sightings, 1u);
}

TEST(GnssFleet, ResetAdoptMapAndOrder) {
  ThreeLanes f;
  f.fixes(10.0);
  const std::vector<NodeIndex> node = {0};
  ASSERT_TRUE(f.fleet.addBelief("picker_1", 10.0, node, {1.0}));
  // A clock jump back: fixes at earlier stamps are accepted again, beliefs are gone.
  EXPECT_FALSE(f.fleet.processFix(*f.fleet.find("picker_1"), f.fixAt(5.0, {0.0, 0.0})).accepted());
  f.fleet.reset();
  EXPECT_EQ(f.fleet.find("picker_1")->beliefs.size(), 0u);
  EXPECT_EQ(f.fleet.find("picker_1")->ingest.counters().accepted, 0u);
  EXPECT_TRUE(f.fleet.processFix(*f.fleet.find("picker_1"), f.fixAt(5.0, {0.0, 0.0})).accepted());
  // A new map: fixes land on it, beliefs (node indices of the old map) are forgotten.
  ASSERT_TRUE(f.fleet.addBelief("picker_1", 5.0, node, {1.0}));
  const auto bigger = ranging_test::latticeMap(30.0, 1.0);
  f.fleet.adoptMap(bigger, f.datum, false);
  EXPECT_EQ(&f.fleet.map(), bigger.get());
  EXPECT_EQ(f.fleet.find("picker_1")->beliefs.size(), 0u);
  EXPECT_TRUE(f.fleet.processFix(*f.fleet.find("picker_1"), f.fixAt(6.0, {25.0, 0.0})).accepted());
  // Association order is the order of addition; a picker listed twice is refused.
  EXPECT_EQ(f.fleet.add("picker_2"), nullptr);
  EXPECT_TRUE(f.fleet.remove("picker_2"));
  EXPECT_FALSE(f.fleet.remove("picker_2"));
  ASSERT_NE(f.fleet.add("picker_2"), nullptr);
  EXPECT_EQ(f.fleet.pickers().back()->ingest.pickerId(), "picker_2");
  EXPECT_EQ(f.fleet.size(), 3u);
}
