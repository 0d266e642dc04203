# `stereohash bench textured`: printed cartons through the texture path, beside a peer made of
# OpenCV's parts (SIFT, FLANN, RANSAC homography, solvePnP, triangulation) when OpenCV's
# features2d and flann are available.
target_sources(stereohash PRIVATE ${CMAKE_CURRENT_LIST_DIR}/bench_textured.cpp)
stereohash_headers(stereohash PRIVATE bench_textured.hpp opencv_texture_peer.hpp)
target_link_libraries(stereohash PRIVATE stereohash_texture_recognizer stereohash_feature_db
                      stereohash_feature_db_builder stereohash_textured_model_files
                      stereohash_sim_world stereohash_eval stereohash_image_files stereohash_camera)
find_package(OpenCV QUIET COMPONENTS core features2d flann calib3d)
if(OpenCV_FOUND)
  target_sources(stereohash PRIVATE ${CMAKE_CURRENT_LIST_DIR}/opencv_texture_peer.cpp)
  target_include_directories(stereohash SYSTEM PRIVATE ${OpenCV_INCLUDE_DIRS})
  target_link_libraries(stereohash PRIVATE ${OpenCV_LIBS})
  target_compile_definitions(stereohash PRIVATE STEREOHASH_OPENCV_PEER)
endif()
