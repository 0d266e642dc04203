# firmware/web/: the commissioning web page (docs/web.md), served by the firmware itself with
# libmicrohttpd (Debian libmicrohttpd-dev), its images encoded with libpng and its hashed
# passwords checked with libcrypt. The page's files are linked in (web_assets.S).
pkg_check_modules(MICROHTTPD REQUIRED IMPORTED_TARGET libmicrohttpd)
find_library(STEREOHASH_LIBCRYPT crypt REQUIRED)
set(STEREOHASH_WEB_DIR ${CMAKE_CURRENT_SOURCE_DIR}/web)
set(STEREOHASH_WEB_ASSETS ${STEREOHASH_WEB_DIR}/assets/index.html ${STEREOHASH_WEB_DIR}/assets/app.js
                          ${STEREOHASH_WEB_DIR}/assets/style.css ${CMAKE_CURRENT_SOURCE_DIR}/stereohash.dbc)
configure_file(web/web_assets.S.in ${CMAKE_CURRENT_BINARY_DIR}/web_assets.S @ONLY)
set_source_files_properties(${CMAKE_CURRENT_BINARY_DIR}/web_assets.S PROPERTIES
                            OBJECT_DEPENDS "${STEREOHASH_WEB_ASSETS}")
stereohash_module(stereohash_fw_web
  SOURCES web/http_server.cpp web/web_auth.cpp web/live_snapshot.cpp web/overlay_edges.cpp
          web/png_encode.cpp web/json_writer.cpp web/status_json.cpp web/web_settings.cpp
          web/recordings.cpp web/pair_capture.cpp web/calibration_pairs.cpp web/web_assets.cpp web/web_app.cpp web/core_target.cpp
          web/web_service.cpp ${CMAKE_CURRENT_BINARY_DIR}/web_assets.S
  HEADERS web/web_limits.hpp web/http_server.hpp web/web_auth.hpp web/live_snapshot.hpp
          web/overlay_edges.hpp web/png_encode.hpp web/json_writer.hpp web/status_json.hpp
          web/web_settings.hpp web/recordings.hpp web/pair_capture.hpp web/calibration_pairs.hpp web/web_assets.hpp web/web_app.hpp
          web/web_target.hpp web/core_target.hpp web/web_service.hpp
  PUBLIC stereohash_fw_core stereohash_can_protocol stereohash_canopen_messages stereohash_hal_camera
         stereohash_hal_can stereohash_camera stereohash_geometry stereohash_model stereohash_base
  PRIVATE stereohash_canopen stereohash_pipeline stereohash_image
          stereohash_input_file PNG::PNG PkgConfig::MICROHTTPD ${STEREOHASH_LIBCRYPT})
