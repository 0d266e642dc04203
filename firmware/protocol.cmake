# CAN protocol to the PLC: frame encoders/decoders shared by the firmware, the simulator demo
# and the tests. Pure computation on CanFrame values, so it links only the CAN types; one writer
# (result_json) prints a result set as JSON to a stream the caller gives.
stereohash_module(stereohash_can_protocol
  SOURCES can_protocol.cpp result_json.cpp
  HEADERS can_protocol.hpp le_bytes.hpp result_json.hpp
  PUBLIC stereohash_hal_can stereohash_geometry stereohash_base)
