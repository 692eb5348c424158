# sensors_vision: LiDAR leg clustering + classifier, cluster tracking (Munkres), 3D cloud people, monocular
# person boxes + bearing, LiDAR-camera fusion. ROS-free library + thin ROS nodes + offline tools.
add_library(picker_localisation_vision
  src/sensors_vision/laser_scan.cpp
  src/sensors_vision/leg_features.cpp
  src/sensors_vision/leg_classifier.cpp
  src/sensors_vision/leg_detector.cpp
  src/sensors_vision/leg_training.cpp
  src/sensors_vision/munkres.cpp
  src/sensors_vision/cluster_tracker.cpp
  src/sensors_vision/lidar_camera_fusion.cpp
  src/sensors_vision/leg_pipeline.cpp
  src/sensors_vision/leg_detector_node_options.cpp
  src/sensors_vision/cloud3d_person_detector.cpp
  src/sensors_vision/person_box_detector.cpp
  src/sensors_vision/box_evaluation.cpp)
target_include_directories(picker_localisation_vision SYSTEM PUBLIC ${OpenCV_INCLUDE_DIRS} ${PCL_INCLUDE_DIRS})
target_compile_definitions(picker_localisation_vision PUBLIC ${PCL_DEFINITIONS})
target_link_libraries(picker_localisation_vision PUBLIC picker_localisation_core ${OpenCV_LIBS} ${PCL_LIBRARIES})
install(TARGETS picker_localisation_vision
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})

# ROS adapters of the area (bag reading, message conversions, node classes).
add_library(picker_localisation_vision_ros src/ros/vision_io.cpp src/ros/leg_detector_node.cpp
  src/ros/camera_detector_node.cpp)
target_link_libraries(picker_localisation_vision_ros PUBLIC picker_localisation_ros picker_localisation_vision)
add_dependencies(picker_localisation_vision_ros ${PROJECT_NAME}_generate_messages_cpp)
install(TARGETS picker_localisation_vision_ros
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})

# Package executables (rosrun picker_localisation <tool>).
function(pl_vision_tool name)
  add_executable(${name} ${ARGN})
  target_link_libraries(${name} picker_localisation_vision_ros)
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})
  install(TARGETS ${name} RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
endfunction()
pl_vision_tool(train_leg_classifier src/tools/train_leg_classifier.cpp)
pl_vision_tool(detect_people src/tools/detect_people.cpp)
pl_vision_tool(bag_detect_legs src/tools/bag_detect_legs.cpp)

pl_add_node(leg_detector src/nodes/leg_detector_main.cpp)
target_link_libraries(leg_detector picker_localisation_vision_ros)
pl_add_node(camera_detector src/nodes/camera_detector_main.cpp)
target_link_libraries(camera_detector picker_localisation_vision_ros)
if(benchmark_FOUND)
  add_executable(bench_legs src/tools/bench_legs.cpp)
  target_link_libraries(bench_legs picker_localisation_vision benchmark::benchmark)
  target_compile_definitions(bench_legs PRIVATE PL_LEG_MODEL="${CMAKE_CURRENT_SOURCE_DIR}/config/leg_classifier.yml")
  set_target_properties(bench_legs PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})
  install(TARGETS bench_legs RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
endif()
