# sensors_ranging: GNSS ingestion, RFID ranging, UWB ranging with the Range Histogram Filter.
# ROS-free core library (namespace picker_localisation::sensors).
add_library(picker_localisation_sensors_ranging
  src/sensors_ranging/gnss_bias.cpp
  src/sensors_ranging/gnss_fleet.cpp
  src/sensors_ranging/gnss_ingest.cpp
  src/sensors_ranging/ranging_node_options.cpp
  src/sensors_ranging/picker_association.cpp
  src/sensors_ranging/rfid_observation_model.cpp
  src/sensors_ranging/range_histogram_filter.cpp
  src/sensors_ranging/uwb_ranging.cpp)
target_link_libraries(picker_localisation_sensors_ranging PUBLIC picker_localisation_core)
install(TARGETS picker_localisation_sensors_ranging ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})

if(benchmark_FOUND)
  if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/src/tools/bench_rhf.cpp)
    add_executable(bench_rhf src/tools/bench_rhf.cpp)
    target_link_libraries(bench_rhf picker_localisation_sensors_ranging benchmark::benchmark)
    set_target_properties(bench_rhf PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})
    install(TARGETS bench_rhf RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})
  endif()
endif()

# ROS adapters and nodes.
add_library(picker_localisation_sensors_ranging_ros
  src/ros/ranging_nodes.cpp
  src/ros/gnss_ingest_node.cpp
  src/ros/rfid_ranging_node.cpp
  src/ros/uwb_ranging_node.cpp)
target_link_libraries(picker_localisation_sensors_ranging_ros PUBLIC picker_localisation_ros picker_localisation_sensors_ranging)
add_dependencies(picker_localisation_sensors_ranging_ros ${PROJECT_NAME}_generate_messages_cpp)
install(TARGETS picker_localisation_sensors_ranging_ros ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})
foreach(node gnss_ingest rfid_ranging uwb_ranging)
  pl_add_node(${node} src/nodes/${node}_main.cpp)
  target_link_libraries(${node} picker_localisation_sensors_ranging_ros)
endforeach()

# bench_fleet: N simulated pickers' NavSatFix through gnss_ingest into tpf_tracker on a private ROS master;
# prints CPU, memory and fix -> belief latency as JSON (issue "Track a whole farm in one process").
add_executable(bench_fleet src/tools/bench_fleet.cpp)
target_link_libraries(bench_fleet picker_localisation_sensors_ranging_ros)
target_compile_definitions(bench_fleet PRIVATE PL_SOURCE_DIR="${CMAKE_CURRENT_SOURCE_DIR}")
add_dependencies(bench_fleet ${PROJECT_NAME}_generate_messages_cpp gnss_ingest tpf_tracker)
set_target_properties(bench_fleet PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})
install(TARGETS bench_fleet RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

# picker_fleet: gnss_ingest and tpf_tracker in one process (no socket between them).
pl_add_node(picker_fleet src/nodes/picker_fleet_main.cpp)
target_link_libraries(picker_fleet picker_localisation_sensors_ranging_ros picker_localisation_tpf_ros)
add_dependencies(bench_fleet picker_fleet)
