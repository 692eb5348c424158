# sensors_ranging tests: core gtests (no roscore), the GNSS bag test, rostests of the three nodes.
pl_add_gtest(test_sensors_ranging test/test_sensors_ranging.cpp LIBS picker_localisation_sensors_ranging)
pl_add_gtest(test_gnss_bag test/test_gnss_bag.cpp LIBS picker_localisation_sensors_ranging_ros)
