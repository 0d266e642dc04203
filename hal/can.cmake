# CAN: the CanBus interface and candump logger (any platform), the SocketCAN backend (Linux
# kernel headers only, so it builds natively and for aarch64) and the simulator (in-process bus
# plus a socketcand TCP server for host tools).
find_package(Threads REQUIRED)

add_library(stereohash_hal_can STATIC
  ${CMAKE_CURRENT_SOURCE_DIR}/can_frame.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/can_log.cpp)
target_link_libraries(stereohash_hal_can PUBLIC stereohash_base)

add_library(stereohash_hal_socketcan STATIC
  ${CMAKE_CURRENT_SOURCE_DIR}/linux/socketcan_bus.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/linux/socketcan_errors.cpp)
target_link_libraries(stereohash_hal_socketcan PUBLIC stereohash_hal_can)

add_library(stereohash_hal_can_sim STATIC
  ${CMAKE_CURRENT_SOURCE_DIR}/sim/can_sim_bus.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/sim/socketcand_text.cpp
  ${CMAKE_CURRENT_SOURCE_DIR}/sim/socketcand_server.cpp)
target_link_libraries(stereohash_hal_can_sim PUBLIC stereohash_hal_can Threads::Threads)
