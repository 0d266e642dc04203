# CAN protocol to the PLC: the result codec and the command codec shared by the firmware, the
# simulator demo and the tests. Pure computation on CanFrame values, so it links only the CAN
# types and the CANopen messages (identifiers, EMCY); one writer (result_json) prints a result set
# as JSON to a stream the caller gives.
stereohash_module(stereohash_can_protocol
  SOURCES result_codec.cpp command_codec.cpp result_json.cpp
  HEADERS result_codec.hpp command_codec.hpp result_json.hpp
  PUBLIC stereohash_canopen_messages stereohash_hal_can stereohash_geometry stereohash_base)

# The controller's side of the result stream (the reassembler of result sets): the simulator's
# demo PLC and the tests link it, the board program does not.
stereohash_module(stereohash_result_assembler
  SOURCES plc/result_assembler.cpp
  HEADERS plc/result_assembler.hpp
  PUBLIC stereohash_can_protocol stereohash_canopen_messages stereohash_hal_can stereohash_base)
