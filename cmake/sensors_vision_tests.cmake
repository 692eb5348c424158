# sensors_vision tests (no roscore): core algorithms; real data (leg bags, vtest.avi from opencv-doc).
pl_add_gtest(test_vision_core test/test_vision_core.cpp LIBS picker_localisation_vision)
# Real data: leg bags + vtest.avi. Bounds measured at commit time with a margin (docs/readme/sensors_vision.md).
pl_add_gtest(test_vision_data test/test_vision_data.cpp LIBS picker_localisation_vision_ros)
target_compile_definitions(test_vision_data PRIVATE PL_MIN_LEG_RECALL=0.30 PL_MIN_LEG_PRECISION=0.25
                           PL_MAX_FALSE_LEGS_PER_SCAN=1.6)
