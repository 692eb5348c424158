# Robot description (URDF via urdfdom): sensor mounts without tf. ROS-free.
find_package(urdfdom REQUIRED)
add_library(picker_localisation_robot src/robot/robot_description.cpp)
target_link_libraries(picker_localisation_robot PUBLIC picker_localisation_core ${urdfdom_LIBRARIES})
target_include_directories(picker_localisation_robot SYSTEM PUBLIC ${urdfdom_INCLUDE_DIRS})
install(TARGETS picker_localisation_robot ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})
