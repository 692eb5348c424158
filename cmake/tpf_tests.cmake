# Topological Particle Filter tests (ROS-free gtests).
pl_add_gtest(test_tpf test/test_tpf.cpp LIBS picker_localisation_tpf)
pl_add_gtest(test_tpf_paper test/test_tpf_paper.cpp LIBS picker_localisation_tpf)
pl_add_gtest(test_tracker_fleet test/test_tracker_fleet.cpp LIBS picker_localisation_tpf)

# rostest: three trackers started from a pickers file by launch/trackers.launch.
add_rostest_gtest(test_tpf_tracker test/tpf_tracker.test test/test_tpf_tracker.cpp)
target_link_libraries(test_tpf_tracker picker_localisation_ros)
add_dependencies(test_tpf_tracker tpf_tracker)

# rostest: periodic prediction on simulated time (/clock).
add_rostest_gtest(test_tpf_tracker_sim_time test/tpf_tracker_sim_time.test test/test_tpf_tracker_sim_time.cpp)
target_link_libraries(test_tpf_tracker_sim_time picker_localisation_ros)
add_dependencies(test_tpf_tracker_sim_time tpf_tracker)
