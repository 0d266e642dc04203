# `stereohash calibrate`: chessboard stereo calibration, writing the recogniser's YAML file;
# `stereohash calibrate-table`: the table pose from a chessboard lying on it (table.yaml);
# `stereohash calibrate-handeye`: the camera's pose in the robot's frame (hand-eye file).
# Needs OpenCV (host only), so these live in stereohash-cv, which `stereohash` runs
# (tools/cv_program.hpp). OpenCV needs RTTI and exceptions, which the embedded flags reaching
# this target through stereohash_camera switch off; source-file options come last and win.
if(TARGET stereohash-cv)
  set(calibrate_sources ${CMAKE_CURRENT_LIST_DIR}/cmd_calibrate.cpp
                        ${CMAKE_CURRENT_LIST_DIR}/cmd_calibrate_table.cpp
                        ${CMAKE_CURRENT_LIST_DIR}/board_detection.cpp
                        ${CMAKE_CURRENT_LIST_DIR}/chessboard.cpp
                        ${CMAKE_CURRENT_LIST_DIR}/cmd_calibrate_handeye.cpp
                        ${CMAKE_CURRENT_LIST_DIR}/handeye.cpp)
  target_sources(stereohash-cv PRIVATE ${calibrate_sources})
  stereohash_headers(stereohash-cv PRIVATE board_detection.hpp chessboard.hpp handeye.hpp)
  set_source_files_properties(${calibrate_sources} PROPERTIES COMPILE_OPTIONS "-frtti;-fexceptions")
  target_include_directories(stereohash-cv PRIVATE ${OpenCV_INCLUDE_DIRS})
  target_link_libraries(stereohash-cv PRIVATE stereohash_camera ${OpenCV_LIBS})
endif()
