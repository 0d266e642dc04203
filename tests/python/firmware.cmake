# stereohash-fw-sim, end to end from a python-can/socketcand PLC with canmatrix decoding:
# 50 triggers with the recognition pipeline against the renderer's ground truth, and a run that
# reports the ground truth itself (CAN path, sequence counters, latency without recognition).
if(TARGET stereohash-fw-sim)
  foreach(_kind pipeline truth)
    if(_kind STREQUAL "pipeline" AND NOT TARGET stereohash_fw_pipeline)
      continue()
    endif()
    add_test(NAME python_firmware_e2e_${_kind}
             COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/test_firmware_e2e.py
                     --firmware $<TARGET_FILE:stereohash-fw-sim>
                     --dbc ${PROJECT_SOURCE_DIR}/firmware/stereohash.dbc
                     --triggers 50 --recognition ${_kind})
    set_tests_properties(python_firmware_e2e_${_kind} PROPERTIES TIMEOUT 600
                         SKIP_RETURN_CODE 77)
    if(CMAKE_CROSSCOMPILING)
      # Runs against the host build; a cross build's binary would need the emulator and hours.
      set_tests_properties(python_firmware_e2e_${_kind} PROPERTIES LABELS host_only)
    endif()
  endforeach()
  # The PDO result mode seen by a PLC that maps only the fixed PDOs: 50 sets through the
  # pipeline with the stream beside it (every answered pose equals the stream's, every
  # ground-truth object found), and the PDO mode alone reporting the ground truth.
  function(stereohash_add_pdo_e2e mode kind)
    if(kind STREQUAL "pipeline" AND NOT TARGET stereohash_fw_pipeline)
      return()
    endif()
    add_test(NAME python_firmware_e2e_${mode}_${kind}
             COMMAND /usr/bin/python3 ${CMAKE_CURRENT_FUNCTION_LIST_DIR}/test_firmware_e2e.py
                     --firmware $<TARGET_FILE:stereohash-fw-sim>
                     --dbc ${PROJECT_SOURCE_DIR}/firmware/stereohash.dbc
                     --triggers 50 --recognition ${kind} --result-mode ${mode} ${ARGN})
    set_tests_properties(python_firmware_e2e_${mode}_${kind} PROPERTIES TIMEOUT 600
                         SKIP_RETURN_CODE 77)
    if(CMAKE_CROSSCOMPILING)
      set_tests_properties(python_firmware_e2e_${mode}_${kind} PROPERTIES LABELS host_only)
    endif()
  endfunction()
  stereohash_add_pdo_e2e(both pipeline --min-recall 1.0)
  # Printed cartons beside the polyhedra: the stereohash program learns their feature database,
  # the firmware reports them over the stream with their ids; every carton found, nothing
  # reported without a ground-truth partner. The cartons found are hidden from the polyhedral
  # path (docs/texture.md, Polyhedra among cartons): 38 of 40 objects found here, 23 without.
  if(TARGET stereohash_fw_pipeline AND TARGET stereohash)
    add_test(NAME python_firmware_e2e_printed
             COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/test_firmware_e2e.py
                     --firmware $<TARGET_FILE:stereohash-fw-sim>
                     --dbc ${PROJECT_SOURCE_DIR}/firmware/stereohash.dbc
                     --triggers 10 --scenes 10 --objects 4 --min-recall 0.85
                     --printed $<TARGET_FILE:stereohash>)
    set_tests_properties(python_firmware_e2e_printed PROPERTIES TIMEOUT 600 SKIP_RETURN_CODE 77)
    if(CMAKE_CROSSCOMPILING)
      set_tests_properties(python_firmware_e2e_printed PROPERTIES LABELS host_only)
    endif()
    # Colour parts: the can and the bracket beside the polyhedra, NV12 frames from the simulated
    # cameras, one model set with HASH3D and SHAPE_VIEWS (docs/firmware.md, Single-colour parts).
    add_test(NAME python_firmware_e2e_colour
             COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/test_firmware_e2e.py
                     --firmware $<TARGET_FILE:stereohash-fw-sim>
                     --dbc ${PROJECT_SOURCE_DIR}/firmware/stereohash.dbc
                     --triggers 10 --scenes 10 --objects 4 --seed 101 --min-recall 0.85
                     --min-colour-recall 0.9 --colour $<TARGET_FILE:stereohash>)
    set_tests_properties(python_firmware_e2e_colour PROPERTIES TIMEOUT 600 SKIP_RETURN_CODE 77)
    if(CMAKE_CROSSCOMPILING)
      set_tests_properties(python_firmware_e2e_colour PROPERTIES LABELS host_only)
    endif()
  endif()
  stereohash_add_pdo_e2e(pdo truth)
endif()
# Replay: stereohash-fw-sim with camera = directory on a rendered set gives the poses that
# `stereohash recognize --scene` gives on the same pairs.
if(TARGET stereohash-fw-sim AND TARGET stereohash AND TARGET stereohash_fw_pipeline)
  add_test(NAME python_firmware_replay
           COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/test_replay.py
                   --firmware $<TARGET_FILE:stereohash-fw-sim> --stereohash $<TARGET_FILE:stereohash>
                   --scenes 4)
  set_tests_properties(python_firmware_replay PROPERTIES TIMEOUT 600)
endif()

# The real boot path (the simulator program) with broken data: fault, EMCY, heartbeat, clear-fault after repair.
if(TARGET stereohash-fw-sim AND TARGET stereohash_default_tables)
  add_test(NAME python_firmware_boot_faults
           COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/test_firmware_boot_faults.py
                   --firmware $<TARGET_FILE:stereohash-fw-sim>
                   --dbc ${PROJECT_SOURCE_DIR}/firmware/stereohash.dbc
                   --table ${PROJECT_BINARY_DIR}/tables/reference_hf5.bin
                   --models ${PROJECT_SOURCE_DIR}/models)
  # The stage's longest test: started first (COST), not left to run alone at the end.
  set_tests_properties(python_firmware_boot_faults PROPERTIES TIMEOUT 300 SKIP_RETURN_CODE 77
                                                              COST 1000)
  if(CMAKE_CROSSCOMPILING)
    set_tests_properties(python_firmware_boot_faults PROPERTIES LABELS host_only)
  endif()
endif()

# The one-camera fallback: one camera silent (each side in turn), EMCY 0x7300, monocular sets
# against the ground truth, clear-fault back to stereo.
if(TARGET stereohash-fw-sim AND TARGET stereohash_fw_pipeline)
  foreach(side right left)
    set(name python_firmware_monocular_${side})
    add_test(NAME ${name}
             COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/test_firmware_monocular.py
                     --firmware $<TARGET_FILE:stereohash-fw-sim>
                     --dbc ${PROJECT_SOURCE_DIR}/firmware/stereohash.dbc --side ${side})
    set_tests_properties(${name} PROPERTIES TIMEOUT 600 SKIP_RETURN_CODE 77)
    if(CMAKE_CROSSCOMPILING)
      set_tests_properties(${name} PROPERTIES LABELS host_only)
    endif()
  endforeach()
endif()

# A command flood and silent connections on the simulated bus (socketcand bridge).
if(TARGET stereohash-fw-sim)
  add_test(NAME python_firmware_flood
           COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/test_firmware_flood.py
                   --firmware $<TARGET_FILE:stereohash-fw-sim> --triggers 2000)
  set_tests_properties(python_firmware_flood PROPERTIES TIMEOUT 300 SKIP_RETURN_CODE 77)
  if(CMAKE_CROSSCOMPILING)
    set_tests_properties(python_firmware_flood PROPERTIES LABELS host_only)
  endif()
endif()
