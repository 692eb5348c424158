// bench_rhf: one Range Histogram Filter update (Sarmento et al. 2024, Eqs. 2-7) on a 20 m x 20 m grid with
// 5 cm cells (400 x 400 cells). Target: <= 1 ms on one core (Sarmento et al. 2024 report 18.3 ms per cycle
// for their implementation).
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "picker_localisation/sensors_ranging/range_histogram_filter.h"

namespace ps = picker_localisation::sensors;

namespace {

// Three anchors as in Sarmento et al. 2024, Table 1 (front-left, front-right, rear), a person 4 m ahead walking
// sideways, ranges at 10 Hz, the robot driving forward at 0.5 m/s.
void runUpdates(benchmark::State& state, bool with_camera, bool moving) {
  ps::RhfOptions o;  // 20 m x 20 m, 0.05 m
  ps::RangeHistogramFilter rhf(o);
  const std::vector<Eigen::Vector2d> anchors = {{0.35, 0.3}, {0.35, -0.3}, {-0.4, 0.0}};
  double t = 0.0;
  for (auto _ : state) {
    t += 0.1;
    const Eigen::Vector2d robot(moving ? 0.5 * t : 0.0, 0.0);
    const Eigen::Vector2d person = robot + Eigen::Vector2d(4.0, std::sin(0.2 * t));
    std::vector<ps::RangeMeasurement> ranges;
    for (const auto& a : anchors) ranges.push_back({a, (person - robot - a).norm(), 0.0225});
    std::vector<ps::BearingMeasurement> bearings;
    if (with_camera) {
      const Eigen::Vector2d rel = person - robot;
      bearings.push_back({Eigen::Vector2d(0.4, 0.0), std::atan2(rel.y(), rel.x() - 0.4), 0.05});
    }
    Eigen::Isometry2d pose = Eigen::Isometry2d::Identity();
    pose.translation() = robot;
    auto est = rhf.update(t, ranges, bearings, pose);
    benchmark::DoNotOptimize(est);
  }
  state.counters["cells"] = rhf.cellsX() * rhf.cellsY();
}

void BM_RhfUpdate_3Uwb(benchmark::State& s) { runUpdates(s, false, false); }
void BM_RhfUpdate_3Uwb_Camera(benchmark::State& s) { runUpdates(s, true, false); }
void BM_RhfUpdate_3Uwb_Camera_MovingRobot(benchmark::State& s) { runUpdates(s, true, true); }

}  // namespace

BENCHMARK(BM_RhfUpdate_3Uwb)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_RhfUpdate_3Uwb_Camera)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_RhfUpdate_3Uwb_Camera_MovingRobot)->Unit(benchmark::kMicrosecond);
BENCHMARK_MAIN();
