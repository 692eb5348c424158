// bench_tpf: cost of one Topological Particle Filter update (Algorithm 1: prediction, JSD, weighting,
// resampling, noise, entropy) versus particle count and versus map size, full TPF and Khan et al. side by
// side. The user counter ns_per_particle_update = CPU time of the calling thread spent in update() /
// (updates x particles): the cost on one core, unaffected by other processes sharing the machine.
//
//   rosrun picker_localisation bench_tpf [--benchmark_filter=...]
#include <benchmark/benchmark.h>

#include <time.h>

#include <memory>
#include <string>
#include <vector>

#include "picker_localisation/topology/synthetic_map.h"
#include "picker_localisation/tpf/topological_particle_filter.h"

using namespace picker_localisation;

namespace {

double threadCpuNs() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e9 * static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec);
}

// GNSS observations of a picker walking lane 1 up and down at 0.5 m/s, 1 Hz, sigma 1 m.
std::vector<core::Observation> walkObservations(const topology::TopologicalMap& map, std::size_t count) {
  const auto& lane = map.laneNodes(map.numLanes() > 1 ? 1 : 0);
  const Eigen::Vector2d a = map.position2d(lane.front()), b = map.position2d(lane.back());
  const double length = (b - a).norm();
  std::vector<core::Observation> out;
  for (std::size_t k = 0; k < count; ++k) {
    const double s = std::fmod(0.5 * static_cast<double>(k), 2.0 * length);
    const bool up = s < length;
    const Eigen::Vector2d dir = (b - a).normalized();
    core::Observation o;
    o.sensor = "gnss";
    o.identifying = true;
    o.picker_id = "picker_1";
    o.velocity = (up ? 0.5 : -0.5) * dir;
    core::setGaussianLikelihood(o, map, a + dir * (up ? s : 2.0 * length - s), Eigen::Matrix2d::Identity());
    out.push_back(std::move(o));
  }
  return out;
}

void runUpdates(benchmark::State& state, std::size_t map_nodes, std::size_t particles,
                const std::string& method) {
  auto map = std::make_shared<const topology::TopologicalMap>(
      topology::makePolytunnelMap(topology::polytunnelSpecWithNodes(map_nodes)));
  tpf::TpfParams params = tpf::TpfParams::presetForMethod(method);
  params.num_particles = particles;
  tpf::TopologicalParticleFilter filter(map, params, 1);
  const auto observations = walkObservations(*map, 400);
  std::size_t k = 0;
  double stamp = 0.0;
  // Warm up: converge on the walk so the benchmark measures tracking, not initialisation.
  for (; k < 20; ++k) {
    core::Observation o = observations[k];
    o.stamp = stamp += 1.0;
    filter.update(o);
  }
  double ns = 0.0;
  std::int64_t updates = 0;
  for (auto _ : state) {
    core::Observation o = observations[k++ % observations.size()];
    o.stamp = stamp += 1.0;
    const double t0 = threadCpuNs();
    benchmark::DoNotOptimize(filter.update(o));
    ns += threadCpuNs() - t0;
    ++updates;
  }
  state.counters["ns_per_particle_update"] =
      ns / (static_cast<double>(updates) * static_cast<double>(particles));
  state.counters["particles"] = static_cast<double>(particles);
  state.counters["map_nodes"] = static_cast<double>(map->numNodes());
  state.counters["support"] = static_cast<double>(filter.belief().nodes.size());
}

void BM_TpfParticles(benchmark::State& s) {
  runUpdates(s, 138, static_cast<std::size_t>(s.range(0)), "tpf");
}
void BM_KhanParticles(benchmark::State& s) {
  runUpdates(s, 138, static_cast<std::size_t>(s.range(0)), "khan_unconnected");
}
void BM_TpfMapSize(benchmark::State& s) {
  runUpdates(s, static_cast<std::size_t>(s.range(0)), 10000, "tpf");
}
void BM_KhanMapSize(benchmark::State& s) {
  runUpdates(s, static_cast<std::size_t>(s.range(0)), 10000, "khan_unconnected");
}

}  // namespace

BENCHMARK(BM_TpfParticles)->Arg(100)->Arg(1000)->Arg(10000)->Arg(100000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_KhanParticles)->Arg(100)->Arg(1000)->Arg(10000)->Arg(100000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_TpfMapSize)->Arg(138)->Arg(1000)->Arg(3000)->Arg(10000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_KhanMapSize)->Arg(138)->Arg(1000)->Arg(3000)->Arg(10000)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
