# sensors_vision tests (no roscore): core algorithms; real data (leg bags, vtest.avi from opencv-doc).
pl_add_gtest(test_vision_core test/test_vision_core.cpp LIBS picker_localisation_vision)
