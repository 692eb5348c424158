// bench_nbs: cost of one Next-Best-Sense plan (all candidates, the TPF what-if per candidate and picker) and
// of the Choquet integral alone. Riseholme map when the package's copy is found, else a synthetic polytunnel.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <memory>
#include <random>

#include "picker_localisation/nbs/next_best_sense_planner.h"
#include "picker_localisation/nbs/tpf_belief_source.h"
#include "picker_localisation/topology/map_io.h"
#include "picker_localisation/topology/synthetic_map.h"

using namespace picker_localisation;

namespace {

std::shared_ptr<const topology::TopologicalMap> benchMap() {
#ifdef PL_NBS_MAP
  if (std::filesystem::exists(PL_NBS_MAP))
    return std::make_shared<const topology::TopologicalMap>(topology::loadMap(PL_NBS_MAP));
#endif
  return std::make_shared<const topology::TopologicalMap>(
      topology::makePolytunnelMap(topology::polytunnelSpecWithNodes(138)));
}

// Filters of `pickers` pickers, each after 5 GNSS-like fixes with 3 m sigma at a random node.
std::vector<std::unique_ptr<tpf::TopologicalParticleFilter>> filters(
    const std::shared_ptr<const topology::TopologicalMap>& map, int pickers) {
  std::mt19937_64 rng(42);
  std::uniform_int_distribution<std::size_t> node(0, map->numNodes() - 1);
  std::vector<std::unique_ptr<tpf::TopologicalParticleFilter>> out;
  for (int k = 0; k < pickers; ++k) {
    out.push_back(std::make_unique<tpf::TopologicalParticleFilter>(map, tpf::TpfParams(), k + 1));
    const Eigen::Vector2d at = map->position2d(static_cast<topology::NodeIndex>(node(rng)));
    for (int s = 0; s < 5; ++s) {
      core::Observation obs;
      obs.stamp = s;
      obs.sensor = "gnss";
      obs.picker_id = "p" + std::to_string(k);
      obs.identifying = true;
      core::setGaussianLikelihood(obs, *map, at, Eigen::Matrix2d::Identity() * 9.0);
      out.back()->update(obs);
    }
  }
  return out;
}

void BM_Plan(benchmark::State& state) {
  auto map = benchMap();
  auto fs = filters(map, static_cast<int>(state.range(0)));
  std::vector<std::unique_ptr<nbs::TpfBeliefSource>> views;
  std::vector<nbs::BeliefSource*> ptrs;
  for (std::size_t k = 0; k < fs.size(); ++k) {
    views.push_back(std::make_unique<nbs::TpfBeliefSource>("p" + std::to_string(k), *fs[k]));
    ptrs.push_back(views.back().get());
  }
  nbs::PlannerConfig cfg;
  cfg.horizon_m = static_cast<double>(state.range(1));
  const nbs::NextBestSensePlanner planner(map, cfg);
  std::size_t queries = 0, candidates = 0;
  for (auto _ : state) {
    const nbs::PlanResult r = planner.plan(0, 1.0, ptrs);
    queries = r.what_if_queries;
    candidates = r.ranked.size();
    benchmark::DoNotOptimize(r.ranked.data());
  }
  state.counters["candidates"] = static_cast<double>(candidates);
  state.counters["what_if_queries"] = static_cast<double>(queries);
  state.counters["nodes"] = static_cast<double>(map->numNodes());
}
// Args: pickers, horizon in metres (0 = whole map).
BENCHMARK(BM_Plan)->Args({1, 0})->Args({3, 0})->Args({3, 20})->Unit(benchmark::kMillisecond);

void BM_Choquet(benchmark::State& state) {
  const nbs::FuzzyMeasure mu = nbs::PlannerConfig().measure();
  std::vector<double> u{0.3, 0.9, 0.1, 0.6};
  for (auto _ : state) {
    benchmark::DoNotOptimize(nbs::choquetIntegral(u, mu));
    u[0] = u[0] > 0.5 ? 0.2 : 0.7;
  }
}
BENCHMARK(BM_Choquet);

}  // namespace

BENCHMARK_MAIN();
