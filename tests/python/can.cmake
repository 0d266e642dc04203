# CAN protocol end to end: python-can over socketcand against the simulated device, frames
# decoded with canmatrix from firmware/stereohash.dbc. --device takes any program honouring the
# contract in test_can_socketcand.py, so the firmware in simulation can replace can_sim_demo.
if(TARGET can_sim_demo)
  set(_device "$<TARGET_FILE:can_sim_demo>")
  if(CMAKE_CROSSCOMPILING_EMULATOR)
    list(JOIN CMAKE_CROSSCOMPILING_EMULATOR " " _emulator)
    set(_device "${_emulator} ${_device}")
  endif()
  foreach(_node 1 42)
    add_test(NAME python_can_socketcand_node${_node}
             COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/test_can_socketcand.py
                     --dbc ${PROJECT_SOURCE_DIR}/firmware/stereohash.dbc
                     --device "${_device}" --node ${_node})
    set_tests_properties(python_can_socketcand_node${_node} PROPERTIES TIMEOUT 180
                         SKIP_RETURN_CODE 77)
  endforeach()
endif()
