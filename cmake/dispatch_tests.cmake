# Dispatcher tests (ROS-free gtests).
pl_add_gtest(test_call_dispatcher test/test_call_dispatcher.cpp LIBS picker_localisation_dispatch)
