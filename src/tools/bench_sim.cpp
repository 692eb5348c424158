// Speed of the farm simulator: simulated seconds per wall second (items/s = simulated seconds/s) on the
// Riseholme map and on large synthetic polytunnels, with every sensor on, and the laser ray cast alone.
#include <benchmark/benchmark.h>

#include "picker_localisation/sim/farm_simulator.h"
#include "picker_localisation/topology/map_io.h"
#include "picker_localisation/topology/synthetic_map.h"

using namespace picker_localisation;

namespace {
topology::TopologicalMap riseholme() {
  return topology::loadMap(std::string(PL_PACKAGE_DIR) + "/config/maps/riseholme.tmap2");
}

void runSim(benchmark::State& state, const topology::TopologicalMap& map, std::size_t robots, bool laser) {
  sim::SimConfig c;
  c.num_robots = robots;
  c.enable.laser = laser;
  sim::FarmSimulator sim(map, c);
  for (auto _ : state) {
    auto out = sim.step(1.0);
    benchmark::DoNotOptimize(out);
  }
  state.SetItemsProcessed(state.iterations());  // simulated seconds
}
}  // namespace

static void BM_RiseholmeAllSensors(benchmark::State& state) {
  static const auto map = riseholme();
  runSim(state, map, static_cast<std::size_t>(state.range(0)), true);
}
BENCHMARK(BM_RiseholmeAllSensors)->Arg(1)->Arg(3);

static void BM_RiseholmeNoLaser(benchmark::State& state) {
  static const auto map = riseholme();
  runSim(state, map, 1, false);
}
BENCHMARK(BM_RiseholmeNoLaser);

static void BM_PolytunnelAllSensors(benchmark::State& state) {
  const auto map = topology::makePolytunnelMap(
      topology::polytunnelSpecWithNodes(static_cast<std::size_t>(state.range(0))));
  runSim(state, map, 1, true);
}
BENCHMARK(BM_PolytunnelAllSensors)->Arg(1000)->Arg(10000);

static void BM_LaserScan(benchmark::State& state) {
  static const auto map = riseholme();
  sim::SimConfig c;
  sim::FarmSimulator sim(map, c);
  const auto scene = sim.laserScene(0);
  std::mt19937_64 rng(1);
  for (auto _ : state) {
    auto scan = sim::castLaser(scene, sim.robotPose(0), c.laser, 0.0, rng);
    benchmark::DoNotOptimize(scan);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_LaserScan);

BENCHMARK_MAIN();
