# CAN: the CanBus interface and candump logger (any platform), the SocketCAN backend (Linux
# kernel headers only, so it builds natively and for aarch64) and the simulator (in-process bus
# plus a socketcand TCP server for host tools).
find_package(Threads REQUIRED)

stereohash_module(stereohash_hal_can
  SOURCES can_frame.cpp can_log.cpp
  HEADERS can.hpp can_log.hpp
  PUBLIC stereohash_base)

stereohash_module(stereohash_hal_socketcan
  SOURCES linux/socketcan_bus.cpp linux/socketcan_errors.cpp
  HEADERS linux/socketcan_bus.hpp linux/socketcan_errors.hpp
  PUBLIC stereohash_hal_can)

stereohash_module(stereohash_hal_can_sim
  SOURCES sim/can_sim_bus.cpp sim/socketcand_text.cpp sim/socketcand_server.cpp
  HEADERS sim/can_sim_bus.hpp sim/socketcand_text.hpp sim/socketcand_server.hpp
  PUBLIC stereohash_hal_can Threads::Threads)
