# Evaluation area: metrics, Table II writers and plot, the ukf_metric baseline (ROS-free), the experiment
# runner, the evaluator node.
add_library(picker_localisation_eval
  src/eval/metrics.cpp
  src/eval/report.cpp
  src/eval/ukf_metric_tracker.cpp)
target_link_libraries(picker_localisation_eval PUBLIC picker_localisation_core opencv_core opencv_imgproc
  opencv_imgcodecs)
target_include_directories(picker_localisation_eval SYSTEM PUBLIC ${OpenCV_INCLUDE_DIRS})
install(TARGETS picker_localisation_eval
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})
