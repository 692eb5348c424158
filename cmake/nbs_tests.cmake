# Tests of the Next-Best-Sense planner.
pl_add_gtest(test_nbs_choquet test/test_nbs_choquet.cpp LIBS picker_localisation_nbs)
pl_add_gtest(test_nbs_planner test/test_nbs_planner.cpp LIBS picker_localisation_nbs)
pl_add_gtest(test_nbs_tpf_planner test/test_nbs_tpf_planner.cpp LIBS picker_localisation_nbs)
add_rostest_gtest(test_nbs_planner_node test/nbs_planner.test test/test_nbs_planner_node.cpp)
target_link_libraries(test_nbs_planner_node picker_localisation_ros picker_localisation_tpf)
pl_add_gtest(test_nbs_ros_adapter test/test_nbs_ros_adapter.cpp LIBS picker_localisation_nbs_ros)
if(TARGET tpf_tracker)
  # nbs_planner against the real tpf_tracker's what-if service.
  add_rostest_gtest(test_nbs_planner_tracker test/nbs_planner_tracker.test test/test_nbs_planner_tracker.cpp)
  target_link_libraries(test_nbs_planner_tracker picker_localisation_ros)
endif()
