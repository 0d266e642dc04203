# stereohash-fw: the board program (also the host simulator). The core and simulator pieces are
# libraries so the tests drive them in-process; Linux backends are linked where they were found.
add_library(stereohash_fw_core STATIC
  ${CMAKE_CURRENT_LIST_DIR}/fw_config.cpp
  ${CMAKE_CURRENT_LIST_DIR}/firmware_core.cpp
  ${CMAKE_CURRENT_LIST_DIR}/canopen_node.cpp
  ${CMAKE_CURRENT_LIST_DIR}/output_frame.cpp
  ${CMAKE_CURRENT_LIST_DIR}/node_id_file.cpp
  ${CMAKE_CURRENT_LIST_DIR}/data_source.cpp
  ${CMAKE_CURRENT_LIST_DIR}/realtime.cpp
  ${CMAKE_CURRENT_LIST_DIR}/sd_notify.cpp)
target_link_libraries(stereohash_fw_core PUBLIC stereohash_can_protocol stereohash_canopen stereohash_hal_can
  stereohash_hal_gpio stereohash_hal_camera stereohash_tables stereohash_default_tables
  stereohash_camera stereohash_embedded_flags Threads::Threads)

add_library(stereohash_fw_sim STATIC ${CMAKE_CURRENT_LIST_DIR}/sim_world.cpp)
target_link_libraries(stereohash_fw_sim PUBLIC stereohash_fw_core stereohash_render
  stereohash_hal_camera_sim stereohash_hal_can_sim stereohash_hal_gpio_sim)

add_executable(stereohash-fw ${CMAKE_CURRENT_LIST_DIR}/fw_main.cpp
                             ${CMAKE_CURRENT_LIST_DIR}/demo_client.cpp)
target_link_libraries(stereohash-fw PRIVATE stereohash_fw_sim stereohash_hal_socketcan)
target_compile_definitions(stereohash-fw PRIVATE
  STEREOHASH_FW_SOURCE_MODELS_DIR="${PROJECT_SOURCE_DIR}/models")
if(TARGET stereohash_pipeline)
  add_library(stereohash_fw_pipeline STATIC ${CMAKE_CURRENT_LIST_DIR}/pipeline_recognition.cpp)
  target_link_libraries(stereohash_fw_pipeline PUBLIC stereohash_fw_core stereohash_pipeline)
  target_link_libraries(stereohash-fw PRIVATE stereohash_fw_pipeline)
  target_compile_definitions(stereohash-fw PRIVATE STEREOHASH_FW_HAVE_PIPELINE=1)
else()
  message(STATUS "stereohash-fw: no recognition pipeline in this tree; only recognition = truth")
endif()
if(TARGET stereohash_hal_camera_libcamera)
  target_link_libraries(stereohash-fw PRIVATE stereohash_hal_camera_libcamera)
  target_compile_definitions(stereohash-fw PRIVATE STEREOHASH_FW_HAVE_LIBCAMERA=1)
endif()
if(TARGET stereohash_hal_gpiod)
  target_link_libraries(stereohash-fw PRIVATE stereohash_hal_gpiod)
  target_compile_definitions(stereohash-fw PRIVATE STEREOHASH_FW_HAVE_GPIOD=1)
endif()

include(GNUInstallDirs)
install(TARGETS stereohash-fw RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/models/ DESTINATION ${CMAKE_INSTALL_DATADIR}/stereohash/models
        FILES_MATCHING PATTERN "*.obj")
install(FILES ${PROJECT_BINARY_DIR}/tables/reference_hf5.bin DESTINATION ${CMAKE_INSTALL_DATADIR}/stereohash/tables)
install(FILES ${CMAKE_CURRENT_LIST_DIR}/stereohash-fw.conf.example
              ${CMAKE_CURRENT_LIST_DIR}/stereohash-fw-sim.conf.example
        DESTINATION ${CMAKE_INSTALL_DATADIR}/stereohash)
install(FILES ${CMAKE_CURRENT_LIST_DIR}/systemd/stereohash-fw.service
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/systemd/system)
