# Answering a picker's call: the ROS-free dispatcher (queued -> assigned -> on the way -> arrived -> to storage
# -> done), shared by the offline runner and the dispatcher node.
add_library(picker_localisation_dispatch src/dispatch/call_dispatcher.cpp)
target_link_libraries(picker_localisation_dispatch PUBLIC picker_localisation_core)
install(TARGETS picker_localisation_dispatch ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})
