# Farm simulator tests (gtest, no roscore).
pl_add_gtest(test_sim test/test_sim.cpp LIBS picker_localisation_sim)
if(TARGET picker_localisation_sensors_ranging)
  pl_add_gtest(test_sim_datum test/test_sim_datum.cpp LIBS picker_localisation_sim picker_localisation_sensors_ranging)
endif()
add_rostest_gtest(test_farm_sim test/farm_sim.test test/test_farm_sim.cpp)
target_link_libraries(test_farm_sim picker_localisation_ros)
pl_add_gtest(test_sim_layout test/test_sim_layout.cpp LIBS picker_localisation_sim_ros)
