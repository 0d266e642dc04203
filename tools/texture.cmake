# `stereohash bench textured`: printed cartons through the texture path, beside a peer made of
# OpenCV's parts (SIFT, FLANN, RANSAC homography, solvePnP, triangulation) when OpenCV's
# features2d and flann are available. The peer is built into stereohash-cv, which
# `stereohash bench textured` runs unless --no-peer is given (tools/cv_program.hpp); stereohash
# itself runs the texture path alone.
set(bench_textured_libs stereohash_texture_recognizer stereohash_feature_db
    stereohash_feature_db_builder stereohash_textured_model_files stereohash_sim_world
    stereohash_eval stereohash_image_files stereohash_camera)
target_sources(stereohash PRIVATE ${CMAKE_CURRENT_LIST_DIR}/bench_textured.cpp)
target_link_libraries(stereohash PRIVATE ${bench_textured_libs})
if(TARGET stereohash-cv)
  find_package(OpenCV QUIET COMPONENTS core features2d flann calib3d)
  target_sources(stereohash-cv PRIVATE ${CMAKE_CURRENT_LIST_DIR}/bench_textured.cpp)
  target_link_libraries(stereohash-cv PRIVATE ${bench_textured_libs})
  if(OpenCV_FOUND)
    target_sources(stereohash-cv PRIVATE ${CMAKE_CURRENT_LIST_DIR}/opencv_texture_peer.cpp)
    target_include_directories(stereohash-cv SYSTEM PRIVATE ${OpenCV_INCLUDE_DIRS})
    target_link_libraries(stereohash-cv PRIVATE ${OpenCV_LIBS})
    target_compile_definitions(stereohash-cv PRIVATE STEREOHASH_OPENCV_PEER)
  endif()
endif()
