# `stereohash bench scenes|synthetic`: the thesis's evaluation grids (rendered scenes through the
# whole pipeline; synthetic 3-D scenes through the recogniser for all hash functions). Needs the
# simulated world and the evaluation library (tools/eval). `bench recorded` runs recorded scene
# sets. Both scoring benches recognise through the facade (bench_recognizer) and share their
# scoring (bench_scoring).
target_sources(stereohash PRIVATE ${CMAKE_CURRENT_LIST_DIR}/cmd_bench.cpp
                                  ${CMAKE_CURRENT_LIST_DIR}/bench_recorded.cpp
                                  ${CMAKE_CURRENT_LIST_DIR}/bench_recognizer.cpp
                                  ${CMAKE_CURRENT_LIST_DIR}/bench_scoring.cpp
                                  ${CMAKE_CURRENT_LIST_DIR}/miss_causes.cpp)
stereohash_headers(stereohash PRIVATE bench_recognizer.hpp bench_scoring.hpp)
target_link_libraries(stereohash PRIVATE stereohash_eval stereohash_pipeline stereohash_sim_world
                      stereohash_table_builder stereohash_default_tables stereohash_model_files
                      stereohash_hashing stereohash_verify stereohash_tables)
# The monocular mode in `bench recorded --monocular|--compare` and `bench scenes --monocular`.
target_sources(stereohash PRIVATE ${CMAKE_CURRENT_LIST_DIR}/mono_misses.cpp)
target_link_libraries(stereohash PRIVATE stereohash_mono stereohash_default_aspects)
stereohash_headers(stereohash PRIVATE mono_misses.hpp)
