// ukf_metric baseline: a straight-line track, identified GNSS vs anonymous LiDAR association, track deletion.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "picker_localisation/eval/ukf_metric_tracker.h"

using namespace picker_localisation::eval;

TEST(UkfMetric, NoiseFreeStraightLineConvergesToTruth) {
  UkfMetricTracker tracker;
  const Eigen::Matrix2d R = Eigen::Matrix2d::Identity() * 0.01;
  for (int k = 0; k <= 30; ++k) {  // 0.8 m/s along x, 0.3 m/s along y, fixes at 1 Hz
    const double t = k;
    ASSERT_TRUE(tracker.addGnss(t, "p1", Eigen::Vector2d(2.0 + 0.8 * t, -1.0 + 0.3 * t), R));
  }
  ASSERT_EQ(tracker.tracks().size(), 1u);
  const MetricTrack& tr = tracker.tracks()[0];
  EXPECT_NEAR(tr.x(2), 0.8, 0.02);
  EXPECT_NEAR(tr.x(3), 0.3, 0.02);
  EXPECT_NEAR(tr.x(0), 26.0, 0.05);
  EXPECT_NEAR(tr.x(1), 8.0, 0.05);
  // Prediction 2 s ahead follows the line.
  tracker.predictTo(32.0);
  EXPECT_NEAR(tracker.estimate("p1")->x(), 2.0 + 0.8 * 32, 0.1);
  EXPECT_NEAR(tracker.estimate("p1")->y(), -1.0 + 0.3 * 32, 0.1);
}

TEST(UkfMetric, NoisyStraightLineBeatsRawFixes) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 1.0);
  UkfTrackerParams params;
  params.acceleration_noise = 0.05;  // a walker at constant speed: little acceleration
  UkfMetricTracker tracker(params);
  const Eigen::Matrix2d R = Eigen::Matrix2d::Identity();
  double raw_sq = 0.0, est_sq = 0.0;
  int n = 0;
  for (int k = 0; k <= 200; ++k) {
    const double t = 0.5 * k;
    const Eigen::Vector2d truth(0.5 * t, 0.0);
    const Eigen::Vector2d z = truth + Eigen::Vector2d(noise(rng), noise(rng));
    tracker.addGnss(t, "p1", z, R);
    if (k >= 40) {
      raw_sq += (z - truth).squaredNorm();
      est_sq += (*tracker.estimate("p1") - truth).squaredNorm();
      ++n;
    }
  }
  EXPECT_LT(std::sqrt(est_sq / n), 0.6 * std::sqrt(raw_sq / n));
  EXPECT_NEAR(tracker.tracks()[0].x(2), 0.5, 0.3);
}

TEST(UkfMetric, LidarRefinesIdentifiedTrackAndSpawnsAnonymousOnes) {
  UkfMetricTracker tracker;
  tracker.addGnss(0.0, "p1", Eigen::Vector2d(0, 0), Eigen::Matrix2d::Identity() * 4.0);
  // Leg detection 1 m away (inside the gate of a 2 m std fix) and one 30 m away (a new anonymous track).
  const std::size_t associated =
      tracker.addDetections(0.1, {Eigen::Vector2d(1.0, 0.0), Eigen::Vector2d(30, 0)});
  EXPECT_EQ(associated, 1u);
  ASSERT_EQ(tracker.tracks().size(), 2u);
  EXPECT_EQ(tracker.tracks()[0].picker_id, "p1");
  EXPECT_GT(tracker.tracks()[0].x(0), 0.9);  // the precise detection dominates
  EXPECT_EQ(tracker.tracks()[1].picker_id, "");
  // Picker 2's first fix near the anonymous track adopts it.
  tracker.addGnss(0.2, "p2", Eigen::Vector2d(30.5, 0.0), Eigen::Matrix2d::Identity() * 1.0);
  ASSERT_EQ(tracker.tracks().size(), 2u);
  EXPECT_EQ(tracker.tracks()[1].picker_id, "p2");
}

TEST(UkfMetric, LostTrackKeepsLastEstimateAndRejectsBadInput) {
  UkfTrackerParams p;
  p.max_position_variance = 4.0;
  UkfMetricTracker tracker(p);
  EXPECT_FALSE(tracker.estimate("p1").has_value());
  tracker.addGnss(0.0, "p1", Eigen::Vector2d(5, 5), Eigen::Matrix2d::Identity() * 0.25);
  EXPECT_FALSE(tracker.addGnss(-1.0, "p1", Eigen::Vector2d(5, 5), Eigen::Matrix2d::Identity()));  // old stamp
  EXPECT_FALSE(tracker.addGnss(1.0, "p1", Eigen::Vector2d(NAN, 5), Eigen::Matrix2d::Identity()));
  tracker.predictTo(60.0);  // a minute without data: variance far above 4 m^2
  EXPECT_TRUE(tracker.tracks().empty());
  ASSERT_TRUE(tracker.estimate("p1").has_value());
  EXPECT_NEAR(tracker.estimate("p1")->x(), 5.0, 1e-9);
}
