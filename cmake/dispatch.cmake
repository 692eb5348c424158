# Answering a picker's call: the ROS-free dispatcher (queued -> assigned -> on the way -> arrived -> to storage
# -> done), shared by the offline runner and the dispatcher node.
add_library(picker_localisation_dispatch src/dispatch/call_dispatcher.cpp src/dispatch/call_input.cpp
  src/dispatch/dispatcher_node_options.cpp)
target_link_libraries(picker_localisation_dispatch PUBLIC picker_localisation_core)
install(TARGETS picker_localisation_dispatch ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})

# The dispatcher node (one per farm).
add_library(picker_localisation_dispatch_ros src/ros/dispatcher_node.cpp)
target_link_libraries(picker_localisation_dispatch_ros PUBLIC picker_localisation_ros picker_localisation_dispatch)
add_dependencies(picker_localisation_dispatch_ros ${PROJECT_NAME}_generate_messages_cpp)
install(TARGETS picker_localisation_dispatch_ros ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})
pl_add_node(dispatcher src/nodes/dispatcher_main.cpp)
target_link_libraries(dispatcher picker_localisation_dispatch_ros)
