pl_add_gtest(test_robot_description test/test_robot_description.cpp LIBS picker_localisation_robot)
# robot.launch: the suite without the simulator.
add_rostest_gtest(test_robot_launch test/robot_launch.test test/test_robot_launch.cpp)
target_link_libraries(test_robot_launch picker_localisation_ros)
# replay.launch is deterministic: a recorded simulated-farm bag replayed twice gives identical beliefs and errors.
# Serial: under a loaded machine message delays could exceed the nodes' ordering latency.
add_test(NAME replay_deterministic
  COMMAND ${CATKIN_DEVEL_PREFIX}/env.sh ${CMAKE_CURRENT_SOURCE_DIR}/test/check_replay.sh ${CMAKE_BINARY_DIR}/replay_check)
set_tests_properties(replay_deterministic PROPERTIES RUN_SERIAL TRUE TIMEOUT 900)
# README.md is assembled from docs/readme/*.md: fail when someone edited one without the other.
add_test(NAME docs_links COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/scripts/check_docs.py)
