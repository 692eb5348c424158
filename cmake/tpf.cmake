# Topological Particle Filter (Navigate-and-Seek Sec. IV): ROS-free library, tracker node, benchmark.
add_library(picker_localisation_tpf
  src/tpf/tpf_params.cpp
  src/tpf/topological_particle_filter.cpp
  src/tpf/tracker_fleet.cpp
  src/tpf/tpf_tracker_node_options.cpp)
target_link_libraries(picker_localisation_tpf PUBLIC picker_localisation_core)
install(TARGETS picker_localisation_tpf ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})

# bench_tpf: ns per particle-update versus particle count and map size (Google Benchmark).
if(benchmark_FOUND)
  add_executable(bench_tpf src/tools/bench_tpf.cpp)
  target_link_libraries(bench_tpf picker_localisation_tpf benchmark::benchmark)
  set_target_properties(bench_tpf PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})
  install(TARGETS bench_tpf RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
endif()

# ROS adapter and the tpf_tracker node (every picker of a farm in one process, one TPF each).
add_library(picker_localisation_tpf_ros src/ros/tpf_tracker_node.cpp src/ros/belief_conversions.cpp)
target_link_libraries(picker_localisation_tpf_ros PUBLIC picker_localisation_ros picker_localisation_tpf)
add_dependencies(picker_localisation_tpf_ros ${PROJECT_NAME}_generate_messages_cpp)
install(TARGETS picker_localisation_tpf_ros ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})
pl_add_node(tpf_tracker src/nodes/tpf_tracker_main.cpp)
target_link_libraries(tpf_tracker picker_localisation_tpf_ros)
