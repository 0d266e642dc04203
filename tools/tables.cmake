target_sources(stereohash PRIVATE ${CMAKE_CURRENT_LIST_DIR}/cmd_tables.cpp)
target_link_libraries(stereohash PRIVATE stereohash_table_builder stereohash_default_tables
                      stereohash_model_files stereohash_tables stereohash_shape_builder
                      stereohash_shape_views stereohash_model_set_writer)
# The aspect tables of the monocular mode: `tables build --hash-2d`, and `tables info`.
target_sources(stereohash PRIVATE ${CMAKE_CURRENT_LIST_DIR}/tables_aspects.cpp)
target_link_libraries(stereohash PRIVATE stereohash_aspect_builder stereohash_default_aspects)
stereohash_headers(stereohash PRIVATE tables_aspects.hpp)
# Printed models: the feature database (tools/tablegen/feature_db_builder).
target_sources(stereohash PRIVATE ${CMAKE_CURRENT_LIST_DIR}/tables_printed.cpp)
stereohash_headers(stereohash PRIVATE tables_printed.hpp)
target_link_libraries(stereohash PRIVATE stereohash_feature_db_builder stereohash_feature_db
                      stereohash_textured_model_files)
# CAD exports (tools/tablegen/cad_import, through assimp): `tables build --models` reads STL, PLY and 3MF.
if(NOT TARGET stereohash_cad_import)
  message(FATAL_ERROR "the host tools read CAD exports with assimp: install Debian's "
                      "libassimp-dev (tools/ci/install-deps.sh does)")
endif()
target_sources(stereohash PRIVATE ${CMAKE_CURRENT_LIST_DIR}/tables_cad.cpp)
stereohash_headers(stereohash PRIVATE tables_cad.hpp)
target_link_libraries(stereohash PRIVATE stereohash_cad_import)
