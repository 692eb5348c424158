# Next-Best-Sense planner (Navigate-and-Seek Sec. V): ROS-free core, ROS node nbs_planner.
add_library(picker_localisation_nbs
  src/nbs/choquet.cpp
  src/nbs/belief_source.cpp
  src/nbs/next_best_sense_planner.cpp
  src/nbs/tray_clock.cpp
  src/nbs/nbs_planner_node_options.cpp)
target_link_libraries(picker_localisation_nbs PUBLIC picker_localisation_core)
# The what-if view of a live TPF (in-process planning: experiment runner, tests).
target_sources(picker_localisation_nbs PRIVATE src/nbs/tpf_belief_source.cpp)
target_link_libraries(picker_localisation_nbs PUBLIC picker_localisation_tpf)
install(TARGETS picker_localisation_nbs
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})

# ROS adapter of the planner node.
add_library(picker_localisation_nbs_ros
  src/ros/what_if_belief_source.cpp
  src/ros/nbs_planner_node.cpp)
target_link_libraries(picker_localisation_nbs_ros PUBLIC picker_localisation_ros picker_localisation_nbs)
add_dependencies(picker_localisation_nbs_ros ${PROJECT_NAME}_generate_messages_cpp)
install(TARGETS picker_localisation_nbs_ros
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})

pl_add_node(nbs_planner src/nodes/nbs_planner_main.cpp)
target_link_libraries(nbs_planner picker_localisation_nbs_ros)

# Benchmark: one plan with the TPF what-if, the Choquet integral.
if(benchmark_FOUND)
  add_executable(bench_nbs src/tools/bench_nbs.cpp)
  target_link_libraries(bench_nbs picker_localisation_nbs benchmark::benchmark)
  target_compile_definitions(bench_nbs PRIVATE PL_NBS_MAP="${CMAKE_CURRENT_SOURCE_DIR}/config/maps/riseholme.tmap2")
  set_target_properties(bench_nbs PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})
  install(TARGETS bench_nbs RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
endif()
