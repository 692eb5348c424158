// rostest (test/fuzz_nodes.test): the running tracker and gnss_ingest fuzzed through their interfaces. Seeded
// mutants of the map (fuzz::mutantMapText, as test_fuzz_inputs feeds the parser) are published on the map
// topic they follow, and the tracker's services get random requests (add_picker with random ids, GNSS topics
// and overrides, remove_picker, what_if with random horizons and hypothetical observations, reset). Every
// request must be answered (an exception in a service callback fails the call), both nodes must stay up, and
// once the valid map is published again the pickers are still tracked from their fixes.
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <picker_localisation/AddPicker.h>
#include <picker_localisation/ListPickers.h>
#include <picker_localisation/PickerBeliefArray.h>
#include <picker_localisation/RemovePicker.h>
#include <picker_localisation/ResetBelief.h>
#include <picker_localisation/WhatIf.h>
#include <sensor_msgs/NavSatFix.h>
#include <std_msgs/String.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <sstream>

#include "fuzz_util.h"
#include "picker_localisation/core/geodetic_datum.h"
#include "picker_localisation/topology/map_io.h"
#include "ranging_rostest_util.h"

namespace pl = picker_localisation;

TEST(FuzzNodes, MapMutantsAndRandomServiceRequests) {
  ros::NodeHandle nh, pnh("~");
  std::string map_file;
  ASSERT_TRUE(pnh.getParam("map_file", map_file));
  std::stringstream buffer;
  buffer << std::ifstream(map_file).rdbuf();
  std_msgs::String original;
  original.data = buffer.str();
  const pl::topology::TopologicalMap map = pl::topology::loadMap(map_file);
  const auto datum = pl::core::GeodeticDatum::load(std::string(PL_PACKAGE_DIR) + "/config/datum.yaml");

  ros::Publisher map_pub = nh.advertise<std_msgs::String>("/topological_map_2", 1, /*latch=*/true);
  map_pub.publish(original);
  ros::Publisher fix_pub = nh.advertise<sensor_msgs::NavSatFix>("/pickers/picker_1/fix", 10);
  std::map<std::string, std::uint32_t> observations;  // picker -> observations counted by its latest belief
  ros::Subscriber fleet = nh.subscribe<pl::PickerBeliefArray>("/pickers/beliefs", 100,
                                                              [&](const pl::PickerBeliefArray::ConstPtr& m) {
                                                                for (const auto& b : m->beliefs)
                                                                  observations[b.picker_id] = b.observations;
                                                              });
  ASSERT_TRUE(ros::service::waitForService("/tpf_tracker/add_picker", ros::Duration(60.0)));
  ASSERT_TRUE(ros::service::waitForService("/pickers/picker_1/what_if", ros::Duration(60.0)));
  ASSERT_TRUE(
      ranging_test::waitFor([&] { return fix_pub.getNumSubscribers() > 0 && fleet.getNumPublishers() > 0; }));
  const Eigen::Vector2d spot(20.0, -20.0);
  auto beliefsKeepComing = [&] {
    const std::uint32_t before = observations["picker_1"];
    ros::Time last;
    return ranging_test::waitFor([&] {
      if (ros::Time::now() > last + ros::Duration(0.2)) {
        last = ros::Time::now();
        fix_pub.publish(ranging_test::fixAt(datum, spot, last));
      }
      return observations["picker_1"] > before;
    });
  };
  ASSERT_TRUE(beliefsKeepComing()) << "no belief from fixes before the fuzzing";

  fuzz::Wild w(21);
  const std::vector<std::string> ids{"picker_7", "picker_8", "p", "picker_1"};
  const std::vector<std::string> topics{"", "/pickers/picker_7/fix", "~fix", "/pickers/picker_1/fix", "a b"};
  const std::vector<std::string> removable{"picker_7", "picker_8", "zz"};  // never the pickers of the file
  auto overrides = [&]() -> std::string {
    std::ostringstream o;
    switch (w.index(6)) {
      case 0:
        return "";
      case 1:
        o << "{num_particles: " << w.value(500, 1e6) << "}";
        return o.str();
      case 2:
        o << "{prediction_rate: " << w.value(1, 100) << "}";
        return o.str();
      case 3:
        o << "{method: " << w.name({"tpf", "khan_connected", "nope"}) << "}";
        return o.str();
      case 4:
        o << "{lane_change_max_hops: " << w.value(6, 1e4) << ", reorder_window: " << w.value(1, 10) << "}";
        return o.str();
      default:
        return w.name({"[1, 2]", "{a: {b: c}}", "{num_particle: 5}"});
    }
  };
  std::size_t calls = 0, answered = 0, mutants = 0;
  std::vector<std::string> added;  // pickers the fuzzing added (removed again at the end)
  for (int i = 0; i < 60; ++i) {
    if (i % 2 == 0) {
      std_msgs::String mutant;
      mutant.data = fuzz::mutantMapText(original.data, i, w);
      map_pub.publish(mutant);
      ++mutants;
    }
    ++calls;
    switch (w.index(4)) {
      case 0: {
        pl::AddPicker a;
        a.request.picker.id = w.name(ids);
        a.request.picker.gnss_topic = topics[w.index(topics.size())];
        a.request.tpf_overrides = overrides();
        answered += ros::service::call("/tpf_tracker/add_picker", a);
        if (a.response.success) added.push_back(a.request.picker.id);
        break;
      }
      case 1: {
        pl::RemovePicker r;
        r.request.id = w.chance(0.5) && !added.empty() ? added[w.index(added.size())] : w.name(removable);
        answered += ros::service::call("/tpf_tracker/remove_picker", r);
        break;
      }
      case 2: {
        pl::WhatIf q;
        q.request.horizon = w.value(5.0, 30.0);
        q.request.seed = static_cast<std::uint32_t>(w.index(1000));
        q.request.with_observation = w.chance(0.5);
        q.request.observation.sensor = w.name({"gnss", "lidar", "rfid"});
        q.request.observation.header.stamp = ros::Time::now();
        for (std::size_t k = w.size(5); k > 0; --k) {
          q.request.observation.nodes.push_back(w.chance(0.8) ? map.node(w.index(map.numNodes())).name
                                                              : "Nowhere");
          q.request.observation.likelihood.push_back(w.value(0.5, 0.5));
        }
        answered +=
            ros::service::call(w.chance(0.5) ? "/pickers/picker_1/what_if" : "/pickers/picker_2/what_if", q);
        break;
      }
      default: {
        pl::ResetBelief r;
        answered += ros::service::call("/pickers/picker_3/reset", r);
        break;
      }
    }
    ros::WallDuration(0.05).sleep();
  }
  EXPECT_EQ(answered, calls) << "a request was not answered (an exception in a service callback?)";
  EXPECT_EQ(mutants, 30u);

  // The valid map again: the nodes adopt it and go on tracking.
  map_pub.publish(original);
  for (const std::string& id : added) {
    pl::RemovePicker r;
    r.request.id = id;
    ros::service::call("/tpf_tracker/remove_picker", r);
  }
  // The mutants reached the tracker: some refused (most are not maps), and it reports them.
  std::string map_counts;  // "adopted / refused"
  ros::Subscriber diag = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 20, [&](const diagnostic_msgs::DiagnosticArray::ConstPtr& a) {
        for (const auto& st : a->status)
          for (const auto& kv : st.values)
            if (kv.key == "map updates adopted / map messages refused") map_counts = kv.value;
      });
  EXPECT_TRUE(ranging_test::waitFor([&] {
    return !map_counts.empty() && std::stoul(map_counts.substr(map_counts.find('/') + 1)) > 0;
  })) << "tpf_tracker reports no refused map (" << map_counts << ")";
  std::vector<std::string> nodes;
  ASSERT_TRUE(ros::master::getNodes(nodes));
  for (const char* n : {"/tpf_tracker", "/gnss_ingest"})
    EXPECT_NE(std::find(nodes.begin(), nodes.end(), n), nodes.end()) << n << " is gone";
  EXPECT_TRUE(beliefsKeepComing()) << "no belief from fixes after the fuzzing";
  pl::ListPickers list;
  ASSERT_TRUE(ros::service::call("/tpf_tracker/list_pickers", list));
  std::vector<std::string> listed;
  for (const auto& p : list.response.pickers) listed.push_back(p.id);
  EXPECT_EQ(listed, (std::vector<std::string>{"picker_1", "picker_2", "picker_3"}));
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_fuzz_nodes");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
