# sensors_ranging tests: core gtests (no roscore), the GNSS bag test, rostests of the three nodes.
pl_add_gtest(test_gnss test/test_gnss.cpp LIBS picker_localisation_sensors_ranging)
pl_add_gtest(test_rfid test/test_rfid.cpp LIBS picker_localisation_sensors_ranging)
pl_add_gtest(test_uwb test/test_uwb.cpp LIBS picker_localisation_sensors_ranging)
pl_add_gtest(test_gnss_fleet test/test_gnss_fleet.cpp LIBS picker_localisation_sensors_ranging)
pl_add_gtest(test_gnss_bag test/test_gnss_bag.cpp LIBS picker_localisation_sensors_ranging_ros)
add_rostest_gtest(test_gnss_ingest_node test/gnss_ingest.test test/test_gnss_ingest_node.cpp)
# The same tests' joint association of one scan, with stamp ordering.
add_rostest(test/gnss_ingest_ordered.test DEPENDENCIES test_gnss_ingest_node)
target_link_libraries(test_gnss_ingest_node picker_localisation_sensors_ranging_ros)
add_rostest_gtest(test_rfid_ranging_node test/rfid_ranging.test test/test_rfid_ranging_node.cpp)
target_link_libraries(test_rfid_ranging_node picker_localisation_sensors_ranging_ros)
add_rostest_gtest(test_uwb_ranging_node test/uwb_ranging.test test/test_uwb_ranging_node.cpp)
target_link_libraries(test_uwb_ranging_node picker_localisation_sensors_ranging_ros)
# rostest: the clock jumps back; gnss_ingest and tpf_tracker reset their time state and beliefs continue.
if(TARGET tpf_tracker)
  add_rostest_gtest(test_clock_jump test/clock_jump.test test/test_clock_jump.cpp)
  target_link_libraries(test_clock_jump picker_localisation_sensors_ranging_ros)
  add_dependencies(test_clock_jump gnss_ingest tpf_tracker)
endif()

# bench_fleet end to end (functional: JSON fields, every fix became a belief; no speed asserted).
add_test(NAME bench_fleet_runs
  COMMAND ${CATKIN_DEVEL_PREFIX}/env.sh ${CMAKE_CURRENT_SOURCE_DIR}/test/check_bench_fleet.sh $<TARGET_FILE:bench_fleet>)
add_dependencies(tests bench_fleet)

# rostest: the map of an LCAS robot (std_msgs/String JSON on /topological_map_2, datum in its meta, a
# transformation); gnss_ingest and tpf_tracker take it from there and /picker_1/current_node is checked.
if(TARGET tpf_tracker)
  add_rostest_gtest(test_lcas_map test/lcas_map.test test/test_lcas_map.cpp)
  target_link_libraries(test_lcas_map picker_localisation_sensors_ranging_ros)
  add_dependencies(test_lcas_map gnss_ingest tpf_tracker)
endif()

# rostest: tpf_tracker and gnss_ingest on a network shared with strangers: bad service requests and bad
# messages on every input are refused with a reply or one log line, every node stays up, beliefs keep coming.
if(TARGET tpf_tracker)
  add_rostest_gtest(test_hostile_inputs test/hostile_inputs.test test/test_hostile_inputs.cpp)
  target_link_libraries(test_hostile_inputs picker_localisation_sensors_ranging_ros)
  add_dependencies(test_hostile_inputs gnss_ingest tpf_tracker)
endif()

# rostest: the running tracker and gnss_ingest fuzzed through the map topic (mutated maps) and the tracker's
# services (random requests).
if(TARGET tpf_tracker)
  add_rostest_gtest(test_fuzz_nodes test/fuzz_nodes.test test/test_fuzz_nodes.cpp)
  target_link_libraries(test_fuzz_nodes picker_localisation_sensors_ranging_ros)
  add_dependencies(test_fuzz_nodes gnss_ingest tpf_tracker)
endif()
