# CAN protocol to the PLC: frame encoders/decoders shared by the firmware, the simulator demo
# and the tests. Pure computation on CanFrame values (no I/O), so it links only the CAN types.
add_library(stereohash_can_protocol STATIC ${CMAKE_CURRENT_SOURCE_DIR}/can_protocol.cpp)
target_link_libraries(stereohash_can_protocol PUBLIC stereohash_hal_can stereohash_base)
