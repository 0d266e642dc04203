# `stereohash calibrate`: chessboard stereo calibration, writing the recogniser's YAML file.
# Needs OpenCV (host only). OpenCV needs RTTI and exceptions, which the embedded flags reaching
# this target through stereohash_camera switch off; source-file options come last and win.
if(OpenCV_FOUND)
  target_sources(stereohash PRIVATE ${CMAKE_CURRENT_LIST_DIR}/cmd_calibrate.cpp)
  set_source_files_properties(${CMAKE_CURRENT_LIST_DIR}/cmd_calibrate.cpp PROPERTIES
                              COMPILE_OPTIONS "-frtti;-fexceptions")
  target_include_directories(stereohash PRIVATE ${OpenCV_INCLUDE_DIRS})
  target_link_libraries(stereohash PRIVATE stereohash_camera ${OpenCV_LIBS})
endif()
