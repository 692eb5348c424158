# Topological Particle Filter (Navigate-and-Seek Sec. IV): ROS-free library, tracker node, benchmark.
add_library(picker_localisation_tpf
  src/tpf/tpf_params.cpp
  src/tpf/topological_particle_filter.cpp)
target_link_libraries(picker_localisation_tpf PUBLIC picker_localisation_core)
install(TARGETS picker_localisation_tpf ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})
