# Dispatcher tests (ROS-free gtests).
pl_add_gtest(test_call_dispatcher test/test_call_dispatcher.cpp LIBS picker_localisation_dispatch)
# The dispatcher node: calls, robots, arrival, storage, cancel, bad calls (rostest).
add_rostest_gtest(test_dispatcher_node test/dispatcher.test test/test_dispatcher_node.cpp)
target_link_libraries(test_dispatcher_node picker_localisation_ros picker_localisation_dispatch)
# A call through the live graph: farm_sim's calls, trackers, planners, the dispatcher (rostest).
add_rostest_gtest(test_dispatcher_graph test/dispatcher_graph.test test/test_dispatcher_graph.cpp)
target_link_libraries(test_dispatcher_graph picker_localisation_ros)
