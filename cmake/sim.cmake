# Farm simulator core (ROS-free): pickers, GNSS error model, robots, sensor models. See docs/readme/sim.md.
add_library(picker_localisation_sim
  src/sim/sim_types.cpp
  src/sim/lane_layout.cpp
  src/sim/picker_motion.cpp
  src/sim/gnss_model.cpp
  src/sim/robot_motion.cpp
  src/sim/sensor_models.cpp
  src/sim/farm_simulator.cpp
  src/sim/sim_config.cpp)
target_link_libraries(picker_localisation_sim PUBLIC picker_localisation_core)
install(TARGETS picker_localisation_sim ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})

# ROS adapter and the farm_sim node.
add_library(picker_localisation_sim_ros src/ros/farm_sim_node.cpp)
# picker_localisation_robot (URDF mounts, cmake/robot.cmake) is defined later; the name resolves at generate time.
target_link_libraries(picker_localisation_sim_ros PUBLIC picker_localisation_ros picker_localisation_sim
  picker_localisation_robot)
add_dependencies(picker_localisation_sim_ros ${PROJECT_NAME}_generate_messages_cpp)
install(TARGETS picker_localisation_sim_ros ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})
pl_add_node(farm_sim src/nodes/farm_sim_main.cpp)
target_link_libraries(farm_sim picker_localisation_sim_ros)

# bench_sim: simulated seconds per wall second.
if(benchmark_FOUND)
  add_executable(bench_sim src/tools/bench_sim.cpp)
  target_link_libraries(bench_sim picker_localisation_sim benchmark::benchmark)
  target_compile_definitions(bench_sim PRIVATE PL_PACKAGE_DIR="${CMAKE_CURRENT_SOURCE_DIR}")
  set_target_properties(bench_sim PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})
  install(TARGETS bench_sim RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
endif()
