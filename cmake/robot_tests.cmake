pl_add_gtest(test_robot_description test/test_robot_description.cpp LIBS picker_localisation_robot)
# robot.launch: the suite without the simulator.
add_rostest_gtest(test_robot_launch test/robot_launch.test test/test_robot_launch.cpp)
target_link_libraries(test_robot_launch picker_localisation_ros)
