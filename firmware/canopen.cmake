# CANopen slave (CiA 301 object dictionary, SDO server, PDOs, EMCY error state; CiA 305 LSS) and
# the EDS written from the same declared table. Pure classes on CanFrame values, no threads.
add_library(stereohash_canopen STATIC
  ${CMAKE_CURRENT_LIST_DIR}/canopen/od_types.cpp
  ${CMAKE_CURRENT_LIST_DIR}/canopen/object_dictionary.cpp
  ${CMAKE_CURRENT_LIST_DIR}/canopen/sdo_server.cpp
  ${CMAKE_CURRENT_LIST_DIR}/canopen/lss_slave.cpp
  ${CMAKE_CURRENT_LIST_DIR}/canopen/error_state.cpp
  ${CMAKE_CURRENT_LIST_DIR}/canopen/pdo.cpp
  ${CMAKE_CURRENT_LIST_DIR}/canopen/result_objects.cpp
  ${CMAKE_CURRENT_LIST_DIR}/canopen/eds_writer.cpp)
target_link_libraries(stereohash_canopen PUBLIC stereohash_can_protocol)
target_compile_definitions(stereohash_canopen PUBLIC
  STEREOHASH_VERSION_MAJOR=${PROJECT_VERSION_MAJOR}
  STEREOHASH_VERSION_MINOR=${PROJECT_VERSION_MINOR}
  STEREOHASH_VERSION="${PROJECT_VERSION}")

# The EDS, written at build time (under the emulator in cross builds) and installed.
add_executable(stereohash-eds ${CMAKE_CURRENT_LIST_DIR}/canopen/eds_main.cpp)
target_link_libraries(stereohash-eds PRIVATE stereohash_canopen)
set(STEREOHASH_EDS ${CMAKE_CURRENT_BINARY_DIR}/stereohash.eds)
add_custom_command(OUTPUT ${STEREOHASH_EDS}
  COMMAND stereohash-eds ${STEREOHASH_EDS}
  DEPENDS stereohash-eds
  COMMENT "Writing the EDS (CiA 306) of the object dictionary")
add_custom_target(stereohash_eds ALL DEPENDS ${STEREOHASH_EDS})
include(GNUInstallDirs)
install(FILES ${STEREOHASH_EDS} DESTINATION ${CMAKE_INSTALL_DATADIR}/stereohash)
