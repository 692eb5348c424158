// Maps, observations and filter parameters shared by the TPF gtests (test_tpf_paper, test_tpf).
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "picker_localisation/topology/synthetic_map.h"
#include "picker_localisation/topology/topological_map.h"
#include "picker_localisation/tpf/topological_particle_filter.h"

namespace tpf_test {

using namespace picker_localisation;
using topology::NodeIndex;
using tpf::Particle;
using tpf::TpfParams;

// Straight lane along +x: n nodes, `spacing` m apart, edges written one way (0 -> 1 -> ... -> n-1).
inline std::shared_ptr<const topology::TopologicalMap> laneMap(std::size_t n = 5, double spacing = 3.0) {
  std::vector<topology::Node> nodes(n);
  std::vector<topology::EdgeSpec> edges;
  for (std::size_t i = 0; i < n; ++i) {
    nodes[i].name = "n" + std::to_string(i);
    nodes[i].position = Eigen::Vector3d(spacing * static_cast<double>(i), 0.0, 0.0);
    if (i > 0) edges.push_back({"e" + std::to_string(i), nodes[i - 1].name, nodes[i].name, "move_base"});
  }
  return std::make_shared<const topology::TopologicalMap>(
      topology::TopologicalMap::build("lane", std::move(nodes), edges));
}

inline std::shared_ptr<const topology::TopologicalMap> polytunnel() {
  return std::make_shared<const topology::TopologicalMap>(
      topology::makePolytunnelMap(topology::PolytunnelSpec()));
}

inline core::Observation obsAt(double stamp, std::vector<NodeIndex> nodes, std::vector<double> l,
                               bool identifying = true, const std::string& sensor = "gnss") {
  core::Observation o;
  o.stamp = stamp;
  o.sensor = sensor;
  o.identifying = identifying;
  o.picker_id = identifying ? "picker_1" : "";
  o.nodes = std::move(nodes);
  o.likelihood = std::move(l);
  return o;
}

// A filter whose particles never move by themselves: no velocity, no noise, no unconnected jumps.
// The paper's filter read literally (the equation and Algorithm 1 tests check the paper's numbers); the
// product's defaults depart from it (TpfParams, docs/readme/tpf.md) and are tested on their own below.
inline TpfParams paperTpf() {
  return TpfParams::presetForMethod("paper_tpf");
}

inline TpfParams staticParams(std::size_t particles = 2000) {
  TpfParams p = paperTpf();
  p.num_particles = particles;
  p.velocity_init_variance = 0.0;
  p.velocity_noise_variance = 0.0;
  p.dwell_noise_min = p.dwell_noise_max = 0.0;
  p.unconnected_jump_probability = 0.0;
  return p;
}

inline std::map<NodeIndex, double> nodeFractions(const std::vector<Particle>& particles) {
  std::map<NodeIndex, double> f;
  for (const auto& p : particles) f[p.node] += 1.0 / static_cast<double>(particles.size());
  return f;
}

}  // namespace tpf_test
