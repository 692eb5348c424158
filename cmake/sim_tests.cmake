# Farm simulator tests (gtest, no roscore).
pl_add_gtest(test_sim test/test_sim.cpp LIBS picker_localisation_sim)
if(TARGET picker_localisation_sensors_ranging)
  pl_add_gtest(test_sim_datum test/test_sim_datum.cpp LIBS picker_localisation_sim picker_localisation_sensors_ranging)
endif()
