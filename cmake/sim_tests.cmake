# Farm simulator tests (gtest, no roscore).
pl_add_gtest(test_sim test/test_sim.cpp LIBS picker_localisation_sim)
