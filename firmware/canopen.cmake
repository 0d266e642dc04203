# The CANopen messages every codec shares: COB-IDs and node ids, NMT, boot-up and heartbeat, EMCY
# (CiA 301), and the little-endian field helpers. Below the PLC protocol and the CANopen slave.
stereohash_module(stereohash_canopen_messages
  SOURCES canopen/cob_id.cpp canopen/nmt.cpp canopen/emcy.cpp
  HEADERS canopen/cob_id.hpp canopen/nmt.hpp canopen/emcy.hpp le_bytes.hpp
  PUBLIC stereohash_hal_can stereohash_base)

# CANopen slave (CiA 301 object dictionary, SDO server, PDOs, EMCY error state; CiA 305 LSS) and
# the EDS written from the same declared table. Pure classes on CanFrame values, no threads.
stereohash_module(stereohash_canopen
  SOURCES canopen/od_types.cpp canopen/object_dictionary.cpp canopen/sdo_server.cpp
          canopen/lss_slave.cpp canopen/error_state.cpp canopen/pdo.cpp canopen/result_objects.cpp
          canopen/eds_writer.cpp
  HEADERS canopen/od_types.hpp canopen/od_table.hpp canopen/object_dictionary.hpp
          canopen/sdo_server.hpp canopen/lss_slave.hpp canopen/error_state.hpp canopen/pdo.hpp
          canopen/result_objects.hpp canopen/eds_writer.hpp
  PUBLIC stereohash_can_protocol stereohash_canopen_messages stereohash_hal_can stereohash_base)
target_compile_definitions(stereohash_canopen PUBLIC
  STEREOHASH_VERSION_MAJOR=${PROJECT_VERSION_MAJOR}
  STEREOHASH_VERSION_MINOR=${PROJECT_VERSION_MINOR}
  STEREOHASH_VERSION="${PROJECT_VERSION}")

# The EDS, written at build time (under the emulator in cross builds) and installed.
add_executable(stereohash-eds canopen/eds_main.cpp)
target_link_libraries(stereohash-eds PRIVATE stereohash_canopen stereohash_warnings)
stereohash_register(stereohash-eds program)
set(STEREOHASH_EDS ${CMAKE_CURRENT_BINARY_DIR}/stereohash.eds)
add_custom_command(OUTPUT ${STEREOHASH_EDS}
  COMMAND stereohash-eds ${STEREOHASH_EDS}
  DEPENDS stereohash-eds
  COMMENT "Writing the EDS (CiA 306) of the object dictionary")
add_custom_target(stereohash_eds ALL DEPENDS ${STEREOHASH_EDS})
include(GNUInstallDirs)
install(FILES ${STEREOHASH_EDS} DESTINATION ${CMAKE_INSTALL_DATADIR}/stereohash)
