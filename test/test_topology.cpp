// Topology core: both loaders on the real Riseholme maps, malformed inputs, every query.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "legacy_tmap.h"
#include "picker_localisation/topology/map_io.h"
#include "picker_localisation/topology/synthetic_map.h"

using namespace picker_localisation::topology;

namespace {
const std::string kTmap2 = std::string(PL_PACKAGE_DIR) + "/config/maps/riseholme.tmap2";
const std::string& kLegacy = picker_localisation::test::legacyRiseholmePath();

std::string errorOf(const std::string& text) {
  try {
    parseMap(text, "bad.tmap2");
  } catch (const MapError& e) {
    return e.what();
  }
  return "";
}

// Linear-scan reference for the k-d tree.
NodeIndex bruteNearest(const TopologicalMap& m, const Eigen::Vector2d& p) {
  NodeIndex best = 0;
  for (NodeIndex i = 1; i < m.numNodes(); ++i)
    if ((m.position2d(i) - p).norm() < (m.position2d(best) - p).norm()) best = i;
  return best;
}
}  // namespace

TEST(Tmap2Loader, RiseholmeCounts) {
  TopologicalMap m = loadMap(kTmap2);
  EXPECT_EQ(m.numNodes(), 138u);
  EXPECT_EQ(m.numDirectedEdges(), 308u);
  EXPECT_EQ(m.numUndirectedEdges(), 154u);  // all bidirectional (data README)
  EXPECT_EQ(m.name(), "riseholme_rtk");
  EXPECT_EQ(m.metricMap(), "riseholme");
  EXPECT_EQ(m.numComponents(), 1u);
  // README bbox: x in [12.4, 31.5], y in [-37.8, 3.0].
  BoundingBox b = m.boundingBox();
  EXPECT_NEAR(b.min_x, 12.4, 0.05);
  EXPECT_NEAR(b.max_x, 31.5, 0.05);
  EXPECT_NEAR(b.min_y, -37.8, 0.05);
  EXPECT_NEAR(b.max_y, 3.0, 0.05);
  // Values read from the file text: WayPoint1 at (14.3593025208, -20.0007381439), edges to WayPoint2, WayPoint5.
  NodeIndex w1 = *m.index("WayPoint1");
  EXPECT_DOUBLE_EQ(m.node(w1).position.x(), 14.3593025208);
  EXPECT_DOUBLE_EQ(m.node(w1).position.y(), -20.0007381439);
  std::set<std::string> succ;
  for (NodeIndex s : m.successors(w1)) succ.insert(m.node(s).name);
  EXPECT_EQ(succ, (std::set<std::string>{"WayPoint2", "WayPoint5"}));
}

TEST(LegacyLoader, LegacyCopyOfRiseholme) {
  namespace fixture = picker_localisation::test;
  TopologicalMap m = loadMap(kLegacy);
  EXPECT_EQ(m.numNodes(), fixture::kLegacyNodes);
  EXPECT_EQ(m.numDirectedEdges(), fixture::kLegacyDirectedEdges);
  EXPECT_EQ(m.numUndirectedEdges(), fixture::kLegacyUndirectedEdges);  // the motion graph stays undirected
  EXPECT_EQ(m.metricMap(), "riseholme_legacy");
  EXPECT_EQ(m.name(), "riseholme_legacy");
  EXPECT_EQ(m.numComponents(), 1u);
  // Direction is kept as in the file: WayPoint2 -> WayPoint1 was dropped, WayPoint1 -> WayPoint2 kept.
  NodeIndex w1 = *m.index("WayPoint1"), w2 = *m.index("WayPoint2"), w5 = *m.index("WayPoint5");
  std::set<NodeIndex> succ(m.successors(w1).begin(), m.successors(w1).end());
  EXPECT_EQ(succ, (std::set<NodeIndex>{w2, w5}));
  for (NodeIndex s : m.successors(w2)) EXPECT_NE(s, w1);
  EXPECT_TRUE(m.connected(w2, w1));  // but the motion graph is undirected
  // Values read from the tmap2 text: WayPoint1 at (14.3593025208, -20.0007381439).
  EXPECT_DOUBLE_EQ(m.node(w1).position.x(), 14.3593025208);
  EXPECT_DOUBLE_EQ(m.node(w1).position.y(), -20.0007381439);
}

TEST(LegacyLoader, ExplicitFormatMismatchIsAnError) {
  EXPECT_THROW(loadMap(kLegacy, MapFormat::kTmap2), MapError);
  EXPECT_THROW(loadMap(kTmap2, MapFormat::kLegacyTmap), MapError);
}

TEST(MalformedMaps, MissingEdgeTarget) {
  std::string e = errorOf(
      "nodes:\n- node: {name: A, pose: {position: {x: 0, y: 0}}, edges: [{edge_id: A_B, node: B, action: x}]}\n");
  EXPECT_NE(e.find("bad.tmap2"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown node 'B'"), std::string::npos) << e;
  EXPECT_NE(e.find("node 'A'"), std::string::npos) << e;
}

TEST(MalformedMaps, DuplicateNodeName) {
  std::string e = errorOf(
      "nodes:\n- node: {name: A, pose: {position: {x: 0, y: 0}}}\n- node: {name: A, pose: {position: {x: 1, y: 0}}}\n");
  EXPECT_NE(e.find("duplicate node name"), std::string::npos) << e;
  EXPECT_NE(e.find("node 'A'"), std::string::npos) << e;
}

TEST(MalformedMaps, NonNumericPose) {
  std::string e = errorOf("nodes:\n- node: {name: A, pose: {position: {x: abc, y: 0}}}\n");
  EXPECT_NE(e.find("not a number: 'abc'"), std::string::npos) << e;
  EXPECT_NE(e.find("field 'node.pose.position.x'"), std::string::npos) << e;
  EXPECT_NE(errorOf("nodes:\n- node: {name: A, pose: {position: {x: .nan, y: 0}}}\n").find("not finite"),
            std::string::npos);
}

TEST(MalformedMaps, MissingPositionField) {
  std::string e = errorOf("nodes:\n- node: {name: A, pose: {position: {x: 1}}}\n");
  EXPECT_NE(e.find("missing field"), std::string::npos) << e;
  EXPECT_NE(e.find("node.pose.position.y"), std::string::npos) << e;
}

TEST(MalformedMaps, EmptyFile) {
  EXPECT_NE(errorOf("").find("empty"), std::string::npos);
  EXPECT_NE(errorOf("   \n# only a comment\n").find("empty"), std::string::npos);
  EXPECT_NE(errorOf("nodes: []\n").find("no nodes"), std::string::npos);
}

TEST(MalformedMaps, WrongTopLevelType) {
  EXPECT_NE(errorOf("42\n").find("not a topological map"), std::string::npos);
  EXPECT_NE(errorOf("name: x\nedges: []\n").find("not a topological map"), std::string::npos);
  EXPECT_NE(errorOf("nodes: {a: 1}\n").find("'nodes' must be a list"), std::string::npos);
  EXPECT_NE(errorOf("- 1\n- 2\n").find("not a mapping"), std::string::npos);
}

TEST(MalformedMaps, SyntaxErrorAndUnreadableFile) {
  EXPECT_NE(errorOf("nodes: [\n").find("YAML syntax error"), std::string::npos);
  try {
    loadMap("/nonexistent/dir/map.tmap2");
    FAIL() << "no exception";
  } catch (const MapError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/map.tmap2: cannot open"), std::string::npos);
  }
}

TEST(Queries, NearestNodeMatchesLinearScan) {
  TopologicalMap m = loadMap(kTmap2);
  for (NodeIndex i = 0; i < m.numNodes(); ++i) EXPECT_EQ(m.nearestNode(m.position2d(i)), i);
  // A grid of probe points over and beyond the bounding box.
  for (double x = 0.0; x <= 45.0; x += 0.77)
    for (double y = -50.0; y <= 15.0; y += 0.93) {
      Eigen::Vector2d p(x, y);
      NodeIndex got = m.nearestNode(p), want = bruteNearest(m, p);
      EXPECT_DOUBLE_EQ((m.position2d(got) - p).norm(), (m.position2d(want) - p).norm());
    }
}

TEST(Queries, NodesWithinMatchesLinearScan) {
  TopologicalMap m = makePolytunnelMap(PolytunnelSpec{});
  for (double r : {0.0, 1.0, 3.1, 7.5}) {
    Eigen::Vector2d p(4.2, 7.7);
    std::vector<NodeIndex> got = m.nodesWithin(p, r);
    std::set<NodeIndex> got_set(got.begin(), got.end()), want;
    for (NodeIndex i = 0; i < m.numNodes(); ++i)
      if ((m.position2d(i) - p).norm() <= r) want.insert(i);
    EXPECT_EQ(got_set, want) << "radius " << r;
  }
  EXPECT_TRUE(m.nodesWithin({0, 0}, -1.0).empty());
}

TEST(Queries, NeighboursEdgeLengthHopsAndPaths) {
  // 2 lanes x 3 nodes: H0-r0_0-r0_1-r0_2-T0, H1-r1_0-r1_1-r1_2-T1, H0-H1, T0-T1.
  PolytunnelSpec spec;
  spec.lanes = 2;
  spec.nodes_per_lane = 3;
  spec.lane_spacing = 1.5;
  spec.node_spacing = 3.0;
  spec.headland_gap = 2.0;
  TopologicalMap m = makePolytunnelMap(spec);
  auto id = [&](const char* n) { return *m.index(n); };
  EXPECT_EQ(m.numNodes(), 10u);
  EXPECT_EQ(m.numUndirectedEdges(), 10u);
  EXPECT_EQ(m.numDirectedEdges(), 20u);
  EXPECT_EQ(m.neighbours(id("r0_1")), (std::vector<NodeIndex>{std::min(id("r0_0"), id("r0_2")),
                                                             std::max(id("r0_0"), id("r0_2"))}));
  EXPECT_DOUBLE_EQ(*m.edgeLength(id("r0_0"), id("r0_1")), 3.0);
  EXPECT_DOUBLE_EQ(*m.edgeLength(id("H0"), id("r0_0")), 2.0);
  EXPECT_FALSE(m.edgeLength(id("r0_0"), id("r1_0")).has_value());  // adjacent lanes are not connected sideways
  EXPECT_EQ(m.hopDistance(id("r0_1"), id("r0_1")), 0);
  EXPECT_EQ(m.hopDistance(id("r0_0"), id("r1_0")), 3);  // r0_0-H0-H1-r1_0
  EXPECT_EQ(m.hopDistance(id("r1_0"), id("r0_0")), 3);  // symmetric, from the cache of another row
  EXPECT_EQ(m.hopDistance(id("r0_1"), id("r1_1")), 5);  // r0_1-r0_0-H0-H1-r1_0-r1_1
  // Path length: r0_0 -> H0 (2) -> H1 (1.5) -> r1_0 (2) = 5.5 m.
  EXPECT_DOUBLE_EQ(m.pathLength(id("r0_0"), id("r1_0")), 5.5);
  EXPECT_EQ(m.shortestPath(id("r0_0"), id("r1_0")),
            (std::vector<NodeIndex>{id("r0_0"), id("H0"), id("H1"), id("r1_0")}));
  EXPECT_DOUBLE_EQ(m.pathLength(id("T1"), id("T1")), 0.0);
  EXPECT_DOUBLE_EQ(m.distance(id("r0_0"), id("r1_0")), 1.5);
  // Every length from one source at once: the same lengths.
  const std::vector<double> from = m.pathLengthsFrom(id("r0_0"));
  ASSERT_EQ(from.size(), m.numNodes());
  EXPECT_DOUBLE_EQ(from[id("r1_0")], 5.5);
  EXPECT_DOUBLE_EQ(from[id("r0_0")], 0.0);
  for (NodeIndex n = 0; n < m.numNodes(); ++n) EXPECT_NEAR(from[n], m.pathLength(id("r0_0"), n), 1e-9);
}

TEST(Queries, UnreachableNodes) {
  std::vector<Node> nodes(3);
  nodes[0].name = "a";
  nodes[1].name = "b";
  nodes[1].position.x() = 1.0;
  nodes[2].name = "island";
  nodes[2].position.x() = 9.0;
  TopologicalMap m = TopologicalMap::build("t", nodes, {{"a_b", "a", "b", ""}});
  EXPECT_EQ(m.numComponents(), 2u);
  EXPECT_EQ(m.hopDistance(0, 2), -1);
  EXPECT_TRUE(std::isinf(m.pathLength(0, 2)));
  EXPECT_TRUE(std::isinf(m.pathLengthsFrom(0)[2]));
  EXPECT_TRUE(std::isinf(m.pathLengthsFrom(3)[0]));  // a source out of range reaches nothing
  EXPECT_TRUE(m.shortestPath(0, 2).empty());
  // Duplicate directed edges are kept once; the reverse counts as another directed edge.
  TopologicalMap d = TopologicalMap::build("t", nodes, {{"1", "a", "b", ""}, {"2", "a", "b", ""}, {"3", "b", "a", ""}});
  EXPECT_EQ(d.numDirectedEdges(), 2u);
  EXPECT_EQ(d.numUndirectedEdges(), 1u);
}

// A T of three edges: a (0,0) - b (4,0) - c (8,0), and b - d (4,3); island e (20,0) has none.
TEST(Queries, NearestEdgePointProjectsOntoTheClosestEdgeAtTheNearestNode) {
  std::vector<Node> nodes(5);
  const double xy[5][2] = {{0, 0}, {4, 0}, {8, 0}, {4, 3}, {20, 0}};
  for (int i = 0; i < 5; ++i) {
    nodes[i].name = std::string(1, static_cast<char>('a' + i));
    nodes[i].position = Eigen::Vector3d(xy[i][0], xy[i][1], 0.0);
  }
  const TopologicalMap m =
      TopologicalMap::build("t", nodes, {{"ab", "a", "b", ""}, {"bc", "b", "c", ""}, {"bd", "b", "d", ""}});
  // 1 m from a along a-b, 0.2 m off it (hand: fraction 1/4 from a).
  TopologicalMap::EdgePoint q = m.nearestEdgePoint({1.0, 0.2});
  EXPECT_EQ(q.from, 0u);
  EXPECT_EQ(q.to, 1u);
  EXPECT_NEAR(q.fraction, 0.25, 1e-12);
  // Nearest node b; the edge to d (0.3 m off) is closer than b-c (1.2 m off): fraction 1.2 / 3 towards d.
  q = m.nearestEdgePoint({4.3, 1.2});
  EXPECT_EQ(q.from, 1u);
  EXPECT_EQ(q.to, 3u);
  EXPECT_NEAR(q.fraction, 0.4, 1e-12);
  // Beyond an end: clamped at the node (fraction 0).
  q = m.nearestEdgePoint({-2.0, 0.0});
  EXPECT_EQ(q.from, 0u);
  EXPECT_EQ(q.fraction, 0.0);
  // A node without edges: no second node.
  q = m.nearestEdgePoint({19.0, 1.0});
  EXPECT_EQ(q.from, 4u);
  EXPECT_EQ(q.to, kInvalidNode);
  EXPECT_EQ(q.fraction, 0.0);
  // Empty map: nothing.
  EXPECT_EQ(TopologicalMap().nearestEdgePoint({0.0, 0.0}).from, kInvalidNode);
}

TEST(Lanes, RowTraversalRuleOnRiseholme) {
  TopologicalMap m = loadMap(kTmap2);
  // 12 rows of 10 nodes joined by row_traversal edges; 18 headland / dock nodes outside every lane.
  ASSERT_EQ(m.numLanes(), 12u);
  std::size_t in_lane = 0;
  for (std::size_t l = 0; l < m.numLanes(); ++l) {
    EXPECT_EQ(m.laneNodes(static_cast<LaneIndex>(l)).size(), 10u);
    in_lane += m.laneNodes(static_cast<LaneIndex>(l)).size();
  }
  EXPECT_EQ(in_lane, 120u);
  EXPECT_EQ(m.lane(*m.index("WayPoint1")), m.lane(*m.index("WayPoint9")));
  EXPECT_NE(m.lane(*m.index("WayPoint1")), m.lane(*m.index("WayPoint10")));
  EXPECT_EQ(m.lane(*m.index("dock_0")), kNoLane);
  EXPECT_EQ(m.laneNameOf(*m.index("dock_0")), "");
}

TEST(Lanes, MassPerLaneSumsASparseBelief) {
  TopologicalMap m = loadMap(kTmap2);
  const NodeIndex w1 = *m.index("WayPoint1"), w9 = *m.index("WayPoint9"), w10 = *m.index("WayPoint10");
  const NodeIndex dock = *m.index("dock_0");
  const auto per_lane = m.massPerLane({w1, w9, w10, dock}, {0.25, 0.25, 0.375, 0.125});
  ASSERT_EQ(per_lane.size(), 3u);
  EXPECT_DOUBLE_EQ(per_lane.at(m.lane(w1)), 0.5);  // WayPoint1 and WayPoint9 share a lane
  EXPECT_DOUBLE_EQ(per_lane.at(m.lane(w10)), 0.375);
  EXPECT_DOUBLE_EQ(per_lane.at(kNoLane), 0.125);
  EXPECT_TRUE(m.massPerLane({}, {}).empty());
}

TEST(Lanes, TagRuleWinsAndChainRuleFallsBack) {
  TopologicalMap tagged = makePolytunnelMap(PolytunnelSpec{});
  EXPECT_EQ(tagged.numLanes(), 12u);
  EXPECT_EQ(tagged.laneNameOf(*tagged.index("r3_4")), "row_3");
  EXPECT_EQ(tagged.lane(*tagged.index("H3")), kNoLane);

  // Chain rule: a 4-node chain a-b-c-d hanging off a junction j with two short stubs.
  std::vector<Node> nodes;
  for (const char* n : {"j", "a", "b", "c", "d", "s1", "s2"}) {
    Node node;
    node.name = n;
    node.position.x() = static_cast<double>(nodes.size());
    nodes.push_back(node);
  }
  std::vector<EdgeSpec> edges{{"", "j", "a", "move_base"}, {"", "a", "b", "move_base"}, {"", "b", "c", "move_base"},
                              {"", "c", "d", "move_base"}, {"", "j", "s1", "move_base"}, {"", "j", "s2", "move_base"}};
  TopologicalMap chain = TopologicalMap::build("chain", nodes, edges);
  ASSERT_EQ(chain.numLanes(), 1u);  // s1, s2 are single-node chains (< kMinChainLaneNodes)
  EXPECT_EQ(chain.laneNodes(0).size(), 4u);
  EXPECT_EQ(chain.lane(*chain.index("j")), kNoLane);
  EXPECT_EQ(chain.lane(*chain.index("s1")), kNoLane);
}

TEST(Lanes, LegacyMapGetsChainLanes) {
  TopologicalMap m = loadMap(kLegacy);
  EXPECT_GE(m.numLanes(), 4u);
  for (std::size_t l = 0; l < m.numLanes(); ++l) {
    const auto& members = m.laneNodes(static_cast<LaneIndex>(l));
    EXPECT_GE(members.size(), kMinChainLaneNodes);
    for (NodeIndex u : members) EXPECT_LE(m.neighbours(u).size(), 2u);
  }
}

TEST(SyntheticMaps, TenThousandNodes) {
  TopologicalMap m = makePolytunnelMap(polytunnelSpecWithNodes(10000));
  EXPECT_GE(m.numNodes(), 9000u);
  EXPECT_LE(m.numNodes(), 11000u);
  EXPECT_EQ(m.numComponents(), 1u);
  EXPECT_EQ(m.numLanes(), polytunnelSpecWithNodes(10000).lanes);
  // Spot-check the k-d tree on the big map.
  for (double x = -2.0; x < 160.0; x += 13.7) {
    Eigen::Vector2d p(x, x * 0.6);
    EXPECT_DOUBLE_EQ((m.position2d(m.nearestNode(p)) - p).norm(), (m.position2d(bruteNearest(m, p)) - p).norm());
  }
  // Hop distances across the block: from the first lane's first node to the last lane's first node.
  PolytunnelSpec s = polytunnelSpecWithNodes(10000);
  NodeIndex a = *m.index("r0_0"), b = *m.index("r" + std::to_string(s.lanes - 1) + "_0");
  EXPECT_EQ(m.hopDistance(a, b), static_cast<int>(s.lanes - 1) + 2);
}

TEST(MapCopy, CopiesAreIndependentAndQueryable) {
  TopologicalMap m = loadMap(kTmap2);
  TopologicalMap c = m;
  EXPECT_EQ(c.numNodes(), m.numNodes());
  EXPECT_EQ(c.nearestNode(m.position2d(5)), 5u);
  EXPECT_EQ(c.hopDistance(0, 17), m.hopDistance(0, 17));
}

// tmap2 `transformation` (LCAS: node poses in its child frame) and the datum of meta.datum_*.
TEST(Tmap2Loader, TransformationAndDatum) {
  const std::string nodes =
      "nodes:\n"
      "- node: {name: A, pose: {position: {x: 1, y: 0}, orientation: {w: 1}}, edges: [{edge_id: A_B, node: B}]}\n"
      "- node: {name: B, pose: {position: {x: 1, y: 2}}}\n";
  const TopologicalMap plain = parseMap(nodes, "plain");
  EXPECT_FALSE(plain.datum().has_value());
  EXPECT_DOUBLE_EQ(plain.position2d(0).x(), 1.0);
  // 90 degrees about z, then (10, -5): (1, 0) -> (10, -4), (1, 2) -> (8, -4).
  const double h = std::sqrt(0.5);
  const std::string turned = nodes +
                             "meta: {last_updated: x, datum_latitude: 53.25, datum_longitude: -0.5, datum_altitude: 12}\n"
                             "transformation: {child: topo_map, parent: map, rotation: {w: " +
                             std::to_string(h) + ", x: 0, y: 0, z: " + std::to_string(h) +
                             "}, translation: {x: 10, y: -5, z: 0}}\n";
  const TopologicalMap m = parseMap(turned, "turned");
  EXPECT_NEAR(m.position2d(0).x(), 10.0, 1e-5);
  EXPECT_NEAR(m.position2d(0).y(), -4.0, 1e-5);
  EXPECT_NEAR(m.position2d(1).x(), 8.0, 1e-5);
  EXPECT_NEAR(m.position2d(1).y(), -4.0, 1e-5);
  // The node's heading turns with the frame (identity -> 90 degrees about z).
  EXPECT_NEAR(m.node(0).orientation[2], h, 1e-5);
  EXPECT_NEAR(m.node(0).orientation[3], h, 1e-5);
  ASSERT_TRUE(m.datum().has_value());
  EXPECT_DOUBLE_EQ(m.datum()->latitude, 53.25);
  EXPECT_DOUBLE_EQ(m.datum()->longitude, -0.5);
  EXPECT_DOUBLE_EQ(m.datum()->altitude, 12.0);
  // A copy keeps the datum; the shipped map (identity transformation, no datum) is unchanged.
  const TopologicalMap copy = m;
  EXPECT_TRUE(copy.datum().has_value());
  const TopologicalMap riseholme = loadMap(kTmap2);
  EXPECT_FALSE(riseholme.datum().has_value());
  // Bad values: one line naming the field.
  EXPECT_NE(errorOf(nodes + "transformation: {rotation: {w: 0, x: 0, y: 0, z: 0}}\n").find("transformation.rotation"),
            std::string::npos);
  EXPECT_NE(errorOf(nodes + "transformation: {translation: {x: abc}}\n").find("transformation.translation.x"),
            std::string::npos);
  EXPECT_NE(errorOf(nodes + "meta: {datum_latitude: 53.2}\n").find("meta.datum_longitude"), std::string::npos);
  EXPECT_NE(errorOf(nodes + "meta: {datum_latitude: 95, datum_longitude: 0}\n").find("out of range"),
            std::string::npos);
}

// A map edited at run time: nodes renamed, removed and moved are counted, and every old node has a place on
// the new map (its own name, else the nearest node to where it was).
TEST(MapChange, RenamedRemovedMovedAndIdentical) {
  const TopologicalMap before = makePolytunnelMap(PolytunnelSpec());
  EXPECT_TRUE(compareMaps(before, before).identical());
  std::vector<Node> nodes = before.nodes();
  std::vector<EdgeSpec> edges;
  for (const Edge& e : before.edges())
    edges.push_back({e.id, before.node(e.source).name, before.node(e.target).name, e.action});
  const std::string renamed_from = nodes[3].name, removed = nodes[7].name, moved = nodes[10].name;
  auto rename = [&](std::string& n) {
    if (n == renamed_from) n = "renamed";
  };
  for (Node& n : nodes) rename(n.name);
  for (EdgeSpec& e : edges) {
    rename(e.source);
    rename(e.target);
  }
  nodes.erase(nodes.begin() + 7);
  edges.erase(std::remove_if(edges.begin(), edges.end(),
                             [&](const EdgeSpec& e) { return e.source == removed || e.target == removed; }),
              edges.end());
  for (Node& n : nodes)
    if (n.name == moved) n.position.x() += 0.5;
  const TopologicalMap after = TopologicalMap::build("edited", nodes, edges);
  const MapChange c = compareMaps(before, after);
  EXPECT_EQ(c.added, 1u);    // "renamed"
  EXPECT_EQ(c.removed, 2u);  // the old name and the removed node
  EXPECT_EQ(c.moved, 1u);
  EXPECT_TRUE(c.edges_changed);
  EXPECT_FALSE(c.datum_changed);
  EXPECT_EQ(c.summary(), "+1 -2 nodes, 1 moved, edges changed");
  ASSERT_EQ(c.old_to_new.size(), before.numNodes());
  EXPECT_EQ(after.node(c.old_to_new[3]).name, "renamed");  // same place, new name
  EXPECT_EQ(c.old_to_new[7], after.nearestNode(before.position2d(7)));
  EXPECT_EQ(after.node(c.old_to_new[10]).name, moved);  // a moved node keeps its name
  EXPECT_EQ(after.node(c.old_to_new[0]).name, before.node(0).name);
}
