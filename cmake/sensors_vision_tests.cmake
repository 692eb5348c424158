# sensors_vision tests (no roscore): core algorithms; real data (leg bags, vtest.avi from opencv-doc).
pl_add_gtest(test_vision_core test/test_vision_core.cpp LIBS picker_localisation_vision)
# Small ONNX models with known outputs for the cv::dnn path (python3-onnx; nothing is downloaded).
set(PL_TEST_ONNX_DIR ${CMAKE_BINARY_DIR}/test_onnx)
add_custom_command(OUTPUT ${PL_TEST_ONNX_DIR}/person_ssd.onnx ${PL_TEST_ONNX_DIR}/wrong_shape.onnx
  COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/test/make_test_onnx.py ${PL_TEST_ONNX_DIR}
  DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/test/make_test_onnx.py
  COMMENT "Generating the test ONNX models")
add_custom_target(test_onnx_models DEPENDS ${PL_TEST_ONNX_DIR}/person_ssd.onnx ${PL_TEST_ONNX_DIR}/wrong_shape.onnx)
if(TARGET test_vision_core)
  add_dependencies(test_vision_core test_onnx_models)
  target_compile_definitions(test_vision_core PRIVATE PL_TEST_ONNX_DIR="${PL_TEST_ONNX_DIR}")
endif()
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
          $<TARGET_FILE:detect_people> ${CMAKE_CURRENT_SOURCE_DIR} ${PL_TEST_DATA})
add_dependencies(tests bag_detect_legs detect_people)
# rostest: the leg_detector node and the offline runner's LegPipeline give identical observations.
if(TARGET picker_localisation_experiment)
  add_rostest_gtest(test_leg_pipeline_parity test/leg_pipeline_parity.test test/test_leg_pipeline_parity.cpp)
  target_link_libraries(test_leg_pipeline_parity picker_localisation_vision_ros picker_localisation_experiment)
  add_dependencies(test_leg_pipeline_parity leg_detector)
endif()
# rostest: camera_detector loads a generated ONNX model through cv::dnn (boxes, confidence, bearing checked).
add_executable(test_camera_detector_onnx EXCLUDE_FROM_ALL test/test_camera_detector_onnx.cpp)
target_link_libraries(test_camera_detector_onnx ${GTEST_LIBRARIES} picker_localisation_ros ${OpenCV_LIBS})
target_include_directories(test_camera_detector_onnx SYSTEM PRIVATE ${OpenCV_INCLUDE_DIRS} ${GTEST_INCLUDE_DIRS})
add_dependencies(test_camera_detector_onnx test_onnx_models camera_detector)
if(TARGET tests)
  add_dependencies(tests test_camera_detector_onnx)
endif()
add_rostest(test/camera_detector_onnx.test DEPENDENCIES test_camera_detector_onnx ARGS model_dir:=${PL_TEST_ONNX_DIR})
