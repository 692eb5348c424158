# Evaluation area: metrics, Table II writers and plot, the ukf_metric baseline (ROS-free), the experiment
# runner, the evaluator node.
add_library(picker_localisation_eval
  src/eval/metrics.cpp
  src/eval/report.cpp
  src/eval/ukf_metric_tracker.cpp)
target_link_libraries(picker_localisation_eval PUBLIC picker_localisation_core opencv_core opencv_imgproc
  opencv_imgcodecs)
target_include_directories(picker_localisation_eval SYSTEM PUBLIC ${OpenCV_INCLUDE_DIRS})

# The experiment runner drives the nodes' own core classes (simulator, front-ends, tracker fleet, planner).
add_library(picker_localisation_experiment src/eval/experiment.cpp)
target_link_libraries(picker_localisation_experiment PUBLIC picker_localisation_eval picker_localisation_sim
  picker_localisation_tpf picker_localisation_vision picker_localisation_sensors_ranging picker_localisation_nbs
  picker_localisation_dispatch)
target_compile_definitions(picker_localisation_experiment PRIVATE PL_EVAL_PACKAGE_DIR="${CMAKE_CURRENT_SOURCE_DIR}")

add_executable(experiment src/tools/experiment.cpp)
target_link_libraries(experiment picker_localisation_experiment)
set_target_properties(experiment PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CATKIN_DEVEL_PREFIX}/${CATKIN_PACKAGE_BIN_DESTINATION})

install(TARGETS picker_localisation_eval picker_localisation_experiment
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})
install(TARGETS experiment RUNTIME DESTINATION ${CATKIN_PACKAGE_BIN_DESTINATION})

# ROS side: the evaluator node.
add_library(picker_localisation_eval_ros src/ros/evaluator_node.cpp)
target_link_libraries(picker_localisation_eval_ros PUBLIC picker_localisation_ros picker_localisation_eval)
add_dependencies(picker_localisation_eval_ros ${PROJECT_NAME}_generate_messages_cpp)
pl_add_node(evaluator src/nodes/evaluator_main.cpp)
target_link_libraries(evaluator picker_localisation_eval_ros)
install(TARGETS picker_localisation_eval_ros
  ARCHIVE DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION}
  LIBRARY DESTINATION ${CATKIN_PACKAGE_LIB_DESTINATION})
