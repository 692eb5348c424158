// RfidObservationModel against hand-computed values: the logistic read model and its read region, negative
// information, failed attempts between reads. No roscore.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include "picker_localisation/core/geodetic_datum.h"
#include "picker_localisation/sensors_ranging/gnss_bias.h"
#include "picker_localisation/sensors_ranging/gnss_ingest.h"
#include "picker_localisation/sensors_ranging/picker_association.h"
#include "picker_localisation/sensors_ranging/range_histogram_filter.h"
#include "picker_localisation/sensors_ranging/ranging_node_options.h"
#include "picker_localisation/sensors_ranging/rfid_observation_model.h"
#include "picker_localisation/sensors_ranging/uwb_ranging.h"
#include "ranging_test_maps.h"

using namespace picker_localisation;
using namespace picker_localisation::sensors;
using picker_localisation::core::DatumConfig;
using picker_localisation::core::GeodeticDatum;
using topology::NodeIndex;

using namespace ranging_test;  // lattice maps, likelihoodAt, nodeAt, twoPickers, riseholmeDatum, kNaN

// ---------------------------------------------------------------------------------------------------------
// RFID

// Logistic read model with the simulator's defaults (p_max 0.95, d50 4 m, width 0.7 m, max_range 8 m,
// min_relative 0.01). Hand-computed: p_read(0) = 0.95 / (1 + e^(-40/7)) = 0.94687672168,
// p_read(4) = 0.95 / 2 = 0.475, p_read(5) = 0.95 / (1 + e^(10/7)) = 0.18365530131,
// p_read(7) = 0.95 / (1 + e^(30/7)) = 0.01289807110; cut-off r_c = 4 + 0.7 ln 99 = 7.2166 m.
TEST(RfidObservationModel, LogisticReadProbabilityLikelihood) {
  auto map = latticeMap(10.0, 1.0);
  RfidModelOptions o;
  o.negative_information = false;
  o.attempt_rate = 0.0;  // the read alone, L = p_read (failed attempts: FailedAttemptsBetweenReadsCount)
  RfidObservationModel rfid(twoPickers(), map, o);
  EXPECT_NEAR(rfid.regionRadius(), 7.2165838951, 1e-9);
  EXPECT_NEAR(rfid.readProbability(0.0), 0.9468767217, 1e-9);
  EXPECT_NEAR(rfid.readProbability(4.0), 0.475, 1e-12);
  EXPECT_EQ(rfid.readProbability(8.5), 0.0);  // beyond max_range
  RfidRead read;
  read.stamp = 1.0;
  read.robot_id = "robot_1";
  read.frame_id = "robot_1/rfid_antenna";
  read.tag_id = "rfid_2";
  RfidResult r = rfid.process(read);
  ASSERT_TRUE(r.accepted());
  const core::Observation& obs = *r.observation;
  EXPECT_EQ(core::validateObservation(obs, *map), "");
  // Lattice points with x^2 + y^2 <= 7.2166^2: 169 (counted by hand/script over the 21 x 21 lattice).
  EXPECT_EQ(obs.nodes.size(), 169u);
  EXPECT_NEAR(likelihoodAt(obs, nodeAt(*map, 0, 0)), 0.9468767217, 1e-9);
  EXPECT_NEAR(likelihoodAt(obs, nodeAt(*map, 4, 0)), 0.475, 1e-12);
  EXPECT_NEAR(likelihoodAt(obs, nodeAt(*map, 0, -4)), 0.475, 1e-12);
  EXPECT_NEAR(likelihoodAt(obs, nodeAt(*map, 5, 0)), 0.1836553013, 1e-9);
  EXPECT_NEAR(likelihoodAt(obs, nodeAt(*map, 7, 0)), 0.0128980711, 1e-9);
  EXPECT_EQ(likelihoodAt(obs, nodeAt(*map, 8, 0)),
            0.0);  // p_read(8) / p_max = 0.0033 < min_relative: not listed
  // A 3 m height difference: 3D distance 5 m for a node 4 m away in the plane.
  RfidModelOptions oh = o;
  oh.height_difference = 3.0;
  RfidObservationModel high(twoPickers(), map, oh);
  EXPECT_NEAR(high.readProbability(4.0), 0.1836553013, 1e-9);
  EXPECT_NEAR(high.regionRadius(), std::sqrt(7.2165838951 * 7.2165838951 - 9.0), 1e-9);
  // Bad parameters.
  RfidModelOptions bad = o;
  bad.read_model = "cone";
  EXPECT_THROW(RfidObservationModel(twoPickers(), map, bad), std::invalid_argument);
  bad = o;
  bad.width = 0.0;
  EXPECT_THROW(RfidObservationModel(twoPickers(), map, bad), std::invalid_argument);
  bad = o;
  bad.min_relative = 1.0;
  EXPECT_THROW(RfidObservationModel(twoPickers(), map, bad), std::invalid_argument);
}

TEST(RfidObservationModel, ReadRegionLikelihoodAndBadInput) {
  auto map = latticeMap(10.0, 1.0);
  RfidModelOptions o;
  o.read_model = "disc";
  o.read_range = 2.0;
  o.negative_information = false;
  RfidObservationModel rfid(twoPickers(), map, o);
  RfidRead read;
  read.stamp = 1.0;
  read.robot_id = "robot_1";
  read.frame_id = "robot_1/rfid_antenna";
  read.tag_id = "rfid_2";
  read.antenna_pose = Eigen::Vector3d(0.0, 0.0, 0.0);
  RfidResult r = rfid.process(read);
  ASSERT_TRUE(r.accepted());
  const core::Observation& obs = *r.observation;
  EXPECT_EQ(obs.picker_id, "picker_2");
  EXPECT_TRUE(obs.identifying);
  EXPECT_EQ(obs.robot_id, "robot_1");
  // Lattice points within 2 m of the origin: 13 (x^2 + y^2 <= 4).
  EXPECT_EQ(obs.nodes.size(), 13u);
  for (std::size_t i = 0; i < obs.nodes.size(); ++i) {
    EXPECT_LE(map->position2d(obs.nodes[i]).norm(), 2.0 + 1e-9);
    EXPECT_EQ(obs.likelihood[i], 1.0);
  }
  EXPECT_EQ(core::validateObservation(obs, *map), "");
  // Directional antenna facing +y with a 45 deg half beam: (0,0), (0,1), (0,2), (1,1), (-1,1) -> 5 nodes.
  RfidModelOptions od = o;
  od.beam_half_angle = M_PI / 4.0 + 1e-9;
  RfidObservationModel beam(twoPickers(), map, od);
  EXPECT_EQ(beam.nodesInReadRegion(Eigen::Vector3d(0.0, 0.0, M_PI / 2.0)).size(), 5u);
  // Bad input.
  RfidRead bad = read;
  bad.tag_id = "stranger";
  EXPECT_EQ(rfid.process(bad).rejection, RfidRejection::kUnknownTag);
  bad = read;
  bad.antenna_pose.x() = kNaN;
  EXPECT_EQ(rfid.process(bad).rejection, RfidRejection::kNotFinite);
  bad = read;
  bad.stamp = 0.5;
  EXPECT_EQ(rfid.process(bad).rejection, RfidRejection::kOutOfOrder);
  // Far from every node: the nearest node carries the read.
  read.stamp = 2.0;
  read.antenna_pose = Eigen::Vector3d(50.0, 0.0, 0.0);
  r = rfid.process(read);
  ASSERT_TRUE(r.accepted());
  ASSERT_EQ(r.observation->nodes.size(), 1u);
  EXPECT_EQ(r.observation->nodes[0], nodeAt(*map, 10.0, 0.0));
  EXPECT_EQ(rfid.counters().accepted, 2u);
  EXPECT_EQ(rfid.counters().unknown_tag, 1u);
}

TEST(RfidObservationModel, LogisticNegativeInformation) {
  auto map = latticeMap(10.0, 1.0);
  RfidModelOptions o;  // logistic, p_detect 0.7: L(n) = 1 - 0.7 p_read(d) / 0.95
  o.negative_window = 5.0;
  o.negative_period = 5.0;
  RfidObservationModel rfid(twoPickers(), map, o);
  RfidRead read;
  read.frame_id = "a";
  read.tag_id = "rfid_1";
  std::size_t negatives = 0;
  for (int i = 0; i <= 5; ++i) {
    read.stamp = i;
    for (const core::Observation& n : rfid.process(read).negative) {
      ++negatives;
      EXPECT_EQ(n.picker_id, "picker_2");
      ASSERT_EQ(n.nodes.size(), map->numNodes());
      EXPECT_EQ(core::validateObservation(n, *map), "");
      EXPECT_NEAR(likelihoodAt(n, nodeAt(*map, 0, 0)), 1.0 - 0.7 * 0.9468767217 / 0.95, 1e-9);  // 0.30230
      EXPECT_NEAR(likelihoodAt(n, nodeAt(*map, 4, 0)), 0.65, 1e-12);                            // 1 - 0.7 / 2
      EXPECT_NEAR(likelihoodAt(n, nodeAt(*map, 7, 0)), 1.0 - 0.7 * 0.0128980711 / 0.95, 1e-9);  // 0.99050
      EXPECT_EQ(likelihoodAt(n, nodeAt(*map, 8, 0)), 1.0);  // beyond the cut-off
    }
  }
  EXPECT_EQ(negatives, 1u);
}

TEST(RfidObservationModel, NegativeInformationForPickersNotRead) {
  auto map = latticeMap(10.0, 1.0);
  RfidModelOptions o;
  o.read_model = "disc";
  o.read_range = 2.0;
  o.negative_window = 5.0;
  o.negative_period = 5.0;
  o.p_detect = 0.7;
  RfidObservationModel rfid(twoPickers(), map, o);
  RfidRead read;
  read.frame_id = "a";
  read.tag_id = "rfid_1";
  std::vector<double> negative_stamps;
  for (int i = 0; i <= 12; ++i) {
    read.stamp = i;
    RfidResult r = rfid.process(read);
    ASSERT_TRUE(r.accepted());
    for (const core::Observation& n : r.negative) {
      EXPECT_EQ(n.picker_id, "picker_2");
      EXPECT_TRUE(n.identifying);
      ASSERT_EQ(n.nodes.size(), map->numNodes());  // every node listed: unlisted would mean 0
      EXPECT_NEAR(likelihoodAt(n, nodeAt(*map, 0, 0)), 0.3, 1e-12);
      EXPECT_NEAR(likelihoodAt(n, nodeAt(*map, 2, 0)), 0.3, 1e-12);
      EXPECT_NEAR(likelihoodAt(n, nodeAt(*map, 3, 0)), 1.0, 1e-12);
      EXPECT_EQ(core::validateObservation(n, *map), "");
      negative_stamps.push_back(read.stamp);
    }
  }
  // Reading since t = 0; the first negative after a full window (t = 5), then once per period.
  EXPECT_EQ(negative_stamps, (std::vector<double>{5.0, 10.0}));
  // picker_2 read at 13 -> no negative for it until its read is older than the window.
  read.tag_id = "rfid_2";
  read.stamp = 13.0;
  EXPECT_TRUE(rfid.process(read).negative.empty());  // picker_1 was read at 12
  read.tag_id = "rfid_1";
  read.stamp = 16.0;
  EXPECT_TRUE(rfid.process(read).negative.empty());  // picker_2 read 3 s ago
}

TEST(RfidObservationModel, FailedAttemptsBetweenReadsCount) {
  // Two reads of one tag by one antenna 2 s apart at attempt_rate 2 Hz: m = round(2 * 2) - 1 = 3 failed
  // attempts, so the second read's likelihood is p (1 - p)^3 (hand values from p_read(0) and p_read(4)). The
  // first read of the tag follows the cap, max_failed_attempts = 10 (the reader was inventorying while the
  // robot came into range), and so does a read after a gap the cap covers (>= 5.5 s at 2 Hz).
  auto map = latticeMap(10.0, 1.0);
  RfidModelOptions o;
  o.negative_information = false;
  RfidObservationModel rfid(twoPickers(), map, o);
  RfidRead read;
  read.stamp = 1.0;
  read.robot_id = "robot_1";
  read.frame_id = "robot_1/rfid_antenna";
  read.tag_id = "rfid_2";
  const double p0 = 0.9468767217, p4 = 0.475;
  auto expectFailed = [&](const RfidResult& r, int m) {
    ASSERT_TRUE(r.accepted());
    // Relative 1e-7: p0 has 10 digits, and (1 - p0)^10 multiplies its relative error by 10 p0 / (1 - p0).
    const double at_antenna = p0 * std::pow(1.0 - p0, m), at_4m = p4 * std::pow(1.0 - p4, m);
    EXPECT_NEAR(likelihoodAt(*r.observation, nodeAt(*map, 0, 0)), at_antenna, 1e-7 * at_antenna);
    EXPECT_NEAR(likelihoodAt(*r.observation, nodeAt(*map, 4, 0)), at_4m, 1e-9 * at_4m);
  };
  expectFailed(rfid.process(read), 10);  // first read
  read.stamp = 3.0;
  const RfidResult second = rfid.process(read);
  expectFailed(second, 3);
  // The tag is now more likely 4 m from the antenna than next to it.
  EXPECT_GT(likelihoodAt(*second.observation, nodeAt(*map, 4, 0)),
            likelihoodAt(*second.observation, nodeAt(*map, 0, 0)));
  read.stamp = 3.5;
  expectFailed(rfid.process(read), 0);  // the next attempt read it again
  read.stamp = 8.5;                     // 5 s: 9 failed attempts
  expectFailed(rfid.process(read), 9);
  read.stamp = 14.0;  // 5.5 s and 60 s: the cap, not 0 (a gap just over 5 s once counted none)
  expectFailed(rfid.process(read), 10);
  read.stamp = 74.0;
  expectFailed(rfid.process(read), 10);
  // After the clock jumped back (reset), a read 2 s after a "previous" one is a first read again: no failed
  // attempts are counted from a read before the jump, the cap as for any first read.
  rfid.reset();
  read.stamp = 1.5;
  expectFailed(rfid.process(read), 10);
  // attempt_rate 0: reads only (the former model).
  o.attempt_rate = 0.0;
  RfidObservationModel plain(twoPickers(), map, o);
  read.stamp = 1.0;
  expectFailed(plain.process(read), 0);
  read.stamp = 3.0;
  expectFailed(plain.process(read), 0);
}
