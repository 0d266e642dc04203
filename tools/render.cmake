# `stereohash render`: simulated stereo pairs for tests, benchmarks and demos.
target_sources(stereohash PRIVATE ${CMAKE_CURRENT_LIST_DIR}/cmd_render.cpp
               ${CMAKE_CURRENT_LIST_DIR}/render_set.cpp)
stereohash_headers(stereohash PRIVATE render_set.hpp)
target_link_libraries(stereohash PRIVATE stereohash_sim_world stereohash_image_files stereohash_camera
                      stereohash_model_files stereohash_tables stereohash_eval)
target_compile_definitions(stereohash PRIVATE
  STEREOHASH_DEFAULT_MODELS_DIR="${PROJECT_SOURCE_DIR}/models")
