# sensors_vision tests (no roscore): core algorithms; real data (leg bags, vtest.avi from opencv-doc).
pl_add_gtest(test_vision_core test/test_vision_core.cpp LIBS picker_localisation_vision)
# Real data: leg bags + vtest.avi. Bounds measured at commit time with a margin (docs/readme/sensors_vision.md).
pl_add_gtest(test_vision_data test/test_vision_data.cpp LIBS picker_localisation_vision_ros)
target_compile_definitions(test_vision_data PRIVATE PL_MIN_LEG_RECALL=0.42 PL_MIN_LEG_PRECISION=0.36
                           PL_MAX_FALSE_LEGS_PER_SCAN=0.9)
# rostest: leg_detector on real scans + static tf; empty scan and missing tf must not kill it.
add_rostest_gtest(test_leg_detector_node test/leg_detector.test test/test_leg_detector_node.cpp)
target_link_libraries(test_leg_detector_node picker_localisation_vision_ros)
# rostest: camera_detector on a vtest.avi frame (bearing, stale frames, rate limit, missing CameraInfo).
add_rostest_gtest(test_camera_detector_node test/camera_detector.test test/test_camera_detector_node.cpp)
target_link_libraries(test_camera_detector_node picker_localisation_ros ${OpenCV_LIBS})
target_include_directories(test_camera_detector_node SYSTEM PRIVATE ${OpenCV_INCLUDE_DIRS})
# Offline tools: CSV headers and rows on real data, usage errors.
add_test(NAME vision_tools_cli
  COMMAND ${CMAKE_CURRENT_SOURCE_DIR}/test/check_vision_tools.sh $<TARGET_FILE:bag_detect_legs>
          $<TARGET_FILE:detect_people> ${CMAKE_CURRENT_SOURCE_DIR} ${PL_SHARED_DATA})
add_dependencies(tests bag_detect_legs detect_people)
# rostest: the leg_detector node and the offline runner's LegPipeline give identical observations (issue 16).
if(TARGET picker_localisation_experiment)
  add_rostest_gtest(test_leg_pipeline_parity test/leg_pipeline_parity.test test/test_leg_pipeline_parity.cpp)
  target_link_libraries(test_leg_pipeline_parity picker_localisation_vision_ros picker_localisation_experiment)
  add_dependencies(test_leg_pipeline_parity leg_detector)
endif()
