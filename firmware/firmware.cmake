# The firmware: the core and its configuration (board and simulator alike), the run of a program
# (firmware_main), and one wiring file per board, each its own program:
#   stereohash-fw      board_linux.cpp: SocketCAN, libgpiod, libcamera; nothing of the simulator
#   stereohash-fw-sim  board_sim.cpp: the simulated bus, GPIO and world, recorded pairs, truth,
#                      the demo PLC
# The core and the simulator pieces are libraries so the tests drive them in-process.
stereohash_module(stereohash_fw_core
  SOURCES fw_config.cpp config_keys.cpp firmware_core.cpp can_health.cpp canopen_node.cpp
          output_frame.cpp node_id_file.cpp recorder.cpp recorded_settings.cpp data_source.cpp
          realtime.cpp sd_notify.cpp core_host_control.cpp core_support.cpp core_trigger_worker.cpp
          core_camera_supervisor.cpp core_can_dispatcher.cpp core_heartbeat_faults.cpp
  HEADERS fw_config.hpp config_keys.hpp firmware_core.hpp fault_bits.hpp core_support.hpp
          can_health.hpp canopen_node.hpp
          output_frame.hpp node_id_file.hpp recorder.hpp recorded_settings.hpp data_source.hpp
          recognition.hpp realtime.hpp sd_notify.hpp
  PUBLIC stereohash_can_protocol stereohash_canopen_messages stereohash_canopen stereohash_hal_can
         stereohash_hal_gpio stereohash_hal_camera stereohash_tables stereohash_default_tables stereohash_camera
         stereohash_geometry stereohash_base stereohash_embedded_flags Threads::Threads
         stereohash_pipeline stereohash_feature_db stereohash_shape_views stereohash_shape
  PRIVATE stereohash_image_files stereohash_image stereohash_input_file)

stereohash_module(stereohash_fw_pipeline
  SOURCES pipeline_recognition.cpp
  HEADERS pipeline_recognition.hpp
  PUBLIC stereohash_fw_core stereohash_recognizer)

stereohash_module(stereohash_fw_main
  SOURCES firmware_main.cpp
  HEADERS board.hpp
  PUBLIC stereohash_fw_core stereohash_canopen stereohash_hal_camera stereohash_hal_can
         stereohash_hal_gpio stereohash_camera stereohash_geometry stereohash_base
  PRIVATE stereohash_fw_pipeline stereohash_recognizer stereohash_can_protocol stereohash_input_file
          stereohash_fw_web)

# The simulator's pieces of the firmware: ground-truth recognition and the simulator's defaults.
stereohash_module(stereohash_fw_sim
  SOURCES truth_recognition.cpp sim_config.cpp
  HEADERS truth_recognition.hpp sim_config.hpp
  PUBLIC stereohash_fw_core stereohash_sim_world stereohash_hal_camera_sim stereohash_hal_can_sim
         stereohash_hal_gpio_sim stereohash_model_files
  PRIVATE stereohash_can_protocol)

add_executable(stereohash-fw board_linux.cpp)
target_link_libraries(stereohash-fw PRIVATE stereohash_fw_main stereohash_hal_socketcan
                      stereohash_warnings)
stereohash_register(stereohash-fw board)
if(TARGET stereohash_hal_camera_libcamera)
  target_link_libraries(stereohash-fw PRIVATE stereohash_hal_camera_libcamera)
  target_compile_definitions(stereohash-fw PRIVATE STEREOHASH_FW_HAVE_LIBCAMERA=1)
endif()
if(TARGET stereohash_hal_gpiod)
  target_link_libraries(stereohash-fw PRIVATE stereohash_hal_gpiod)
  target_compile_definitions(stereohash-fw PRIVATE STEREOHASH_FW_HAVE_GPIOD=1)
endif()

add_executable(stereohash-fw-sim board_sim.cpp demo_client.cpp)
target_link_libraries(stereohash-fw-sim PRIVATE stereohash_fw_main stereohash_fw_sim
                      stereohash_hal_can_sim stereohash_hal_gpio_sim stereohash_hal_camera_sim
                      stereohash_sim_world stereohash_can_protocol stereohash_canopen_messages
                      stereohash_result_assembler stereohash_model stereohash_base
                      stereohash_fw_core stereohash_camera stereohash_input_file
                      stereohash_warnings)
stereohash_headers(stereohash-fw-sim PRIVATE demo_client.hpp)
stereohash_register(stereohash-fw-sim program)
target_compile_definitions(stereohash-fw-sim PRIVATE
  STEREOHASH_FW_SOURCE_MODELS_DIR="${PROJECT_SOURCE_DIR}/models")

include(GNUInstallDirs)
install(TARGETS stereohash-fw stereohash-fw-sim RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/models/ DESTINATION ${CMAKE_INSTALL_DATADIR}/stereohash/models
        FILES_MATCHING PATTERN "*.obj")
install(FILES ${PROJECT_BINARY_DIR}/tables/reference_hf5.bin DESTINATION ${CMAKE_INSTALL_DATADIR}/stereohash/tables)
install(FILES ${CMAKE_CURRENT_LIST_DIR}/stereohash-fw.conf.example
              ${CMAKE_CURRENT_LIST_DIR}/stereohash-fw-sim.conf.example
        DESTINATION ${CMAKE_INSTALL_DATADIR}/stereohash)
install(FILES ${CMAKE_CURRENT_LIST_DIR}/systemd/stereohash-fw.service
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/systemd/system)
