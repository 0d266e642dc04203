# CAN protocol to the PLC: frame encoders/decoders shared by the firmware, the simulator demo
# and the tests. Pure computation on CanFrame values (no I/O), so it links only the CAN types.
stereohash_module(stereohash_can_protocol
  SOURCES can_protocol.cpp
  HEADERS can_protocol.hpp le_bytes.hpp
  PUBLIC stereohash_hal_can stereohash_geometry stereohash_base)
