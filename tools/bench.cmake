# `stereohash bench scenes|synthetic`: the thesis's evaluation grids (rendered scenes through the
# whole pipeline; synthetic 3-D scenes through the recogniser for all hash functions). Needs the
# simulator's renderer (hal/render.cmake). `bench recorded` runs recorded scene sets.
if(TARGET stereohash_render)
  target_sources(stereohash PRIVATE ${CMAKE_CURRENT_LIST_DIR}/cmd_bench.cpp
                                    ${CMAKE_CURRENT_LIST_DIR}/bench_recorded.cpp
                                    ${CMAKE_CURRENT_LIST_DIR}/miss_causes.cpp
                                    ${PROJECT_SOURCE_DIR}/tests/pipeline/rendered_eval.cpp)
  if(STEREOHASH_BUILD_TESTS)
    target_link_libraries(stereohash PRIVATE stereohash_synth)
  else()
    target_sources(stereohash PRIVATE ${PROJECT_SOURCE_DIR}/tests/support/synthetic_scene.cpp
                                      ${PROJECT_SOURCE_DIR}/tests/support/truth_pose_fit.cpp)
  endif()
  target_link_libraries(stereohash PRIVATE stereohash_pipeline stereohash_render
                        stereohash_table_builder stereohash_default_tables)
  target_compile_definitions(stereohash PRIVATE
                             STEREOHASH_DEFAULT_MODELS_DIR="${PROJECT_SOURCE_DIR}/models")
endif()
