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
