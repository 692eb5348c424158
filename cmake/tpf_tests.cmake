# Topological Particle Filter tests (ROS-free gtests).
pl_add_gtest(test_tpf test/test_tpf.cpp LIBS picker_localisation_tpf)
