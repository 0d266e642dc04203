target_sources(stereohash PRIVATE ${CMAKE_CURRENT_LIST_DIR}/cmd_tables.cpp)
target_link_libraries(stereohash PRIVATE stereohash_table_builder stereohash_default_tables
                      stereohash_model_files stereohash_tables)
