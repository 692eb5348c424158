# Evaluation area: metrics, Table II writers and plot, the ukf_metric baseline (ROS-free), the experiment
# runner, the evaluator node.
add_library(picker_localisation_eval
  src/eval/metrics.cpp
  src/eval/report.cpp
  src/eval/ukf_metric_tracker.cpp)
target_link_libraries(picker_localisation_eval PUBLIC picker_localisation_core opencv_core opencv_imgproc
  opencv_imgcodecs)
target_include_directories(picker_localisation_eval SYSTEM PUBLIC ${OpenCV_INCLUDE_DIRS})

# The experiment runner uses the other areas' core libraries that exist in this build; a method needing a
# missing one is reported unavailable at run time (PL_HAVE_<X> tells the source what is there).
add_library(picker_localisation_experiment src/eval/experiment.cpp)
target_link_libraries(picker_localisation_experiment PUBLIC picker_localisation_eval)
target_compile_definitions(picker_localisation_experiment PRIVATE PL_EVAL_PACKAGE_DIR="${CMAKE_CURRENT_SOURCE_DIR}")
# Deferred to the end of the top-level file: the nbs area is included after this one.
function(pl_eval_link_components)
  set(have "")
  foreach(pair "SIM:picker_localisation_sim" "TPF:picker_localisation_tpf" "VISION:picker_localisation_vision"
               "RANGING:picker_localisation_sensors_ranging" "RANGING:picker_localisation_ranging"
               "NBS:picker_localisation_nbs")
    string(REPLACE ":" ";" pair_list "${pair}")
    list(GET pair_list 0 flag)
    list(GET pair_list 1 lib)
    if(flag STREQUAL "NBS" AND (NOT "TPF" IN_LIST have
       OR NOT EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/src/nbs/tpf_belief_source.cpp))
      continue()
    endif()
    if(TARGET ${lib} AND NOT flag IN_LIST have)
      list(APPEND have ${flag})
      target_link_libraries(picker_localisation_experiment PUBLIC ${lib})
      target_compile_definitions(picker_localisation_experiment PRIVATE PL_HAVE_${flag})
    endif()
  endforeach()
  message(STATUS "eval: experiment runner built with: ${have}")
endfunction()
cmake_language(DEFER CALL pl_eval_link_components)

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
