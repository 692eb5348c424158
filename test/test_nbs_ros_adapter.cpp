// nbs_planner's message side without a roscore: PickerBelief -> node masses (bad entries rejected and
// counted), the what-if source falling back to the published belief when no service is there.
#include <gtest/gtest.h>

#include <cmath>

#include "picker_localisation/ros/what_if_belief_source.h"
#include "picker_localisation/topology/synthetic_map.h"

using namespace picker_localisation;

namespace {
std::shared_ptr<const topology::TopologicalMap> smallMap() {
  topology::PolytunnelSpec spec;
  spec.lanes = 3;
  spec.nodes_per_lane = 4;
  return std::make_shared<const topology::TopologicalMap>(topology::makePolytunnelMap(spec));
}
}  // namespace

TEST(NbsRosAdapter, MassesFromBeliefRejectsUnknownNodesAndBadMasses) {
  auto map = smallMap();
  picker_localisation::PickerBelief b;
  b.picker_id = "p";
  b.nodes = {"r0_1", "r1_2", "Nowhere", "r2_0", "r2_1"};
  b.masses = {0.2, 0.6, 0.5, std::nan(""), -1.0};
  std::size_t rejected = 0;
  const nbs::NodeMasses m = ros_adapter::massesFromBelief(b, *map, &rejected);
  ASSERT_EQ(m.size(), map->numNodes());
  EXPECT_EQ(rejected, 3u);
  EXPECT_NEAR(m[*map->index("r0_1")], 0.25, 1e-12);  // renormalised over the valid entries
  EXPECT_NEAR(m[*map->index("r1_2")], 0.75, 1e-12);
  // Sizes that differ count as one more rejection; nothing valid gives an empty result.
  b.nodes = {"Nowhere"};
  b.masses = {1.0, 2.0};
  EXPECT_TRUE(ros_adapter::massesFromBelief(b, *map, &rejected).empty());
  EXPECT_EQ(rejected, 2u);
  // Masses near the double's range sum to infinity: still a distribution, not all zero.
  b.nodes = {"r0_1", "r1_2"};
  b.masses = {1e308, 1e308};
  const nbs::NodeMasses huge = ros_adapter::massesFromBelief(b, *map, &rejected);
  ASSERT_EQ(huge.size(), map->numNodes());
  EXPECT_NEAR(huge[*map->index("r0_1")], 0.5, 1e-12);
  EXPECT_NEAR(huge[*map->index("r1_2")], 0.5, 1e-12);
  b.nodes = {"r0_1", "r0_1"};  // one node at 2e308: infinite, refused
  EXPECT_TRUE(ros_adapter::massesFromBelief(b, *map, &rejected).empty());
}

TEST(NbsRosAdapter, WhatIfSourceFallsBackToThePublishedBelief) {
  auto map = smallMap();
  picker_localisation::PickerBelief b;
  b.picker_id = "p";
  b.nodes = {"r0_1", "r0_2"};
  b.masses = {0.4, 0.6};
  b.estimated_node = "r0_1";  // the tracker's own MAP estimate wins over the argmax of the masses
  ros_adapter::WhatIfBeliefSource s("p", map, b, nullptr, 1);
  EXPECT_EQ(s.estimatedNode(), *map->index("r0_1"));
  const nbs::NodeMasses prior = s.predicted(10.0);
  EXPECT_TRUE(s.usedFallback());
  EXPECT_NEAR(prior[*map->index("r0_2")], 0.6, 1e-12);
  core::Observation read;
  read.sensor = "rfid";
  read.identifying = true;
  read.picker_id = "p";
  read.nodes = {*map->index("r0_1")};
  read.likelihood = {1.0};
  const nbs::NodeMasses post = s.posterior(10.0, read);
  EXPECT_NEAR(post[*map->index("r0_1")], 1.0, 1e-12);
  EXPECT_EQ(s.calls(), 0u);
}
