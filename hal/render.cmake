# Host simulator camera: image files (PGM/PNG) and the stereo scene renderer. No OpenCV here:
# the firmware links these in simulation builds.
add_library(stereohash_image_files STATIC
  ${CMAKE_CURRENT_LIST_DIR}/sim/image_files.cpp
  ${CMAKE_CURRENT_LIST_DIR}/sim/inflate.cpp
  ${CMAKE_CURRENT_LIST_DIR}/sim/deflate.cpp)
target_link_libraries(stereohash_image_files PUBLIC stereohash_base)

add_library(stereohash_render STATIC
  ${CMAKE_CURRENT_LIST_DIR}/sim/render/ray_caster.cpp
  ${CMAKE_CURRENT_LIST_DIR}/sim/render/renderer.cpp
  ${CMAKE_CURRENT_LIST_DIR}/sim/render/scene_generator.cpp
  ${CMAKE_CURRENT_LIST_DIR}/sim/render/model_directory.cpp)
target_link_libraries(stereohash_render PUBLIC stereohash_camera stereohash_model stereohash_base)
