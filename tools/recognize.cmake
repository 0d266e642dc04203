# `stereohash recognize`: the whole pipeline on one stereo pair from image files, with JSON and
# overlay output. Own image I/O (hal/sim/image_files), no OpenCV.
target_sources(stereohash PRIVATE ${CMAKE_CURRENT_LIST_DIR}/cmd_recognize.cpp
                                  ${CMAKE_CURRENT_LIST_DIR}/overlay.cpp
                                  ${CMAKE_CURRENT_LIST_DIR}/recorded_pair.cpp
                                  ${CMAKE_CURRENT_LIST_DIR}/recognize_texture.cpp)
stereohash_headers(stereohash PRIVATE recognize_texture.hpp)
target_link_libraries(stereohash PRIVATE stereohash_pipeline stereohash_recognizer stereohash_image_files
                      stereohash_default_tables stereohash_tables stereohash_camera stereohash_stereo
                      stereohash_texture_recognizer stereohash_feature_db
                      stereohash_shape_views stereohash_input_file)
# One camera: `recognize --left L` (or --right, or --monocular with --scene).
target_sources(stereohash PRIVATE ${CMAKE_CURRENT_LIST_DIR}/mono_setup.cpp)
target_link_libraries(stereohash PRIVATE stereohash_mono stereohash_default_aspects
                      stereohash_verify)
stereohash_headers(stereohash PRIVATE mono_setup.hpp)
