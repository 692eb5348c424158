// rostest: topological_map_server publishes the Riseholme map and its markers latched, and serves the map.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <gtest/gtest.h>
#include <picker_localisation/GetTopologicalMap.h>
#include <picker_localisation/TopologicalMap.h>
#include <ros/ros.h>
#include <visualization_msgs/MarkerArray.h>

namespace {
template <class M>
boost::shared_ptr<const M> waitLatched(const std::string& topic) {
  // A subscriber that connects after the publish only sees the message because it is latched.
  return ros::topic::waitForMessage<M>(topic, ros::Duration(30.0));
}
}  // namespace

TEST(MapServer, LatchedMap) {
  ros::Duration(0.5).sleep();  // connect after the server published
  auto map = waitLatched<picker_localisation::TopologicalMap>("/picker_localisation/topological_map");
  ASSERT_TRUE(map);
  EXPECT_EQ(map->nodes.size(), 138u);
  EXPECT_EQ(map->edges.size(), 308u);
  EXPECT_EQ(map->lanes.size(), 12u);
  EXPECT_EQ(map->header.frame_id, "map");
  EXPECT_EQ(map->name, "riseholme_rtk");
  for (const auto& e : map->edges) {
    ASSERT_LT(e.source, map->nodes.size());
    ASSERT_LT(e.target, map->nodes.size());
    EXPECT_GT(e.length, 0.0);
  }
}

TEST(MapServer, LatchedMarkers) {
  auto markers = waitLatched<visualization_msgs::MarkerArray>("/topological_map/markers");
  ASSERT_TRUE(markers);
  ASSERT_GE(markers->markers.size(), 2u);
  EXPECT_EQ(markers->markers[0].ns, "nodes");
  EXPECT_EQ(markers->markers[0].points.size(), 138u);
  EXPECT_EQ(markers->markers[1].ns, "edges");
  EXPECT_EQ(markers->markers[1].points.size(), 308u);  // 154 undirected edges, 2 points each
}

TEST(MapServer, Service) {
  ASSERT_TRUE(ros::service::waitForService("/get_topological_map", ros::Duration(30.0)));
  picker_localisation::GetTopologicalMap srv;
  ASSERT_TRUE(ros::service::call("/get_topological_map", srv));
  EXPECT_EQ(srv.response.map.nodes.size(), 138u);
}

TEST(MapServer, Diagnostics) {
  bool found = false;
  for (int i = 0; i < 10 && !found; ++i) {
    auto d =
        ros::topic::waitForMessage<diagnostic_msgs::DiagnosticArray>("/diagnostics", ros::Duration(60.0));
    ASSERT_TRUE(d);
    for (const auto& s : d->status)
      if (s.name.find("topological map") != std::string::npos) {
        found = true;
        EXPECT_EQ(s.level, diagnostic_msgs::DiagnosticStatus::OK);
        bool nodes = false;
        for (const auto& kv : s.values) nodes |= (kv.key == "nodes" && kv.value == "138");
        EXPECT_TRUE(nodes);
      }
  }
  EXPECT_TRUE(found);
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_map_server");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
