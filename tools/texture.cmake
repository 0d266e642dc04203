# `stereohash bench textured`: printed cartons through the texture path, beside a peer made of
# OpenCV's parts (SIFT, FLANN, RANSAC homography, solvePnP, triangulation) when OpenCV's
# features2d and flann are available. Needs the simulator's renderer for --rendered.
if(TARGET stereohash_render)
  target_sources(stereohash PRIVATE ${CMAKE_CURRENT_LIST_DIR}/bench_textured.cpp)
  target_link_libraries(stereohash PRIVATE stereohash_texture_recognizer
                        stereohash_feature_db_builder stereohash_render)
  find_package(OpenCV QUIET COMPONENTS core features2d flann calib3d)
  if(OpenCV_FOUND)
    target_sources(stereohash PRIVATE ${CMAKE_CURRENT_LIST_DIR}/opencv_texture_peer.cpp)
    target_include_directories(stereohash SYSTEM PRIVATE ${OpenCV_INCLUDE_DIRS})
    target_link_libraries(stereohash PRIVATE ${OpenCV_LIBS})
    target_compile_definitions(stereohash PRIVATE STEREOHASH_OPENCV_PEER)
  endif()
endif()
