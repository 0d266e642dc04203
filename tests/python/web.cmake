# The commissioning web page under hostile clients (many connections, slowloris, oversized
# requests, path traversal, writes without a login, a request flood) while a PLC triggers over
# CAN: every trigger answered, heartbeats in every phase, nothing written.
if(TARGET stereohash-fw-sim)
  add_test(NAME python_web_hostile
           COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/test_web_hostile.py
                   --firmware $<TARGET_FILE:stereohash-fw-sim>)
  set_tests_properties(python_web_hostile PROPERTIES TIMEOUT 300)
  if(CMAKE_CROSSCOMPILING)
    set_tests_properties(python_web_hostile PROPERTIES LABELS host_only)
  endif()
endif()

# The page over HTTPS: served, logged into (Secure cookie), plain HTTP refused on its port; a key
# of another certificate refused at start while the node keeps its heartbeat.
if(TARGET stereohash-fw-sim)
  add_test(NAME python_web_tls
           COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/test_web_tls.py
                   --firmware $<TARGET_FILE:stereohash-fw-sim>)
  set_tests_properties(python_web_tls PROPERTIES TIMEOUT 300 SKIP_RETURN_CODE 77)
  if(CMAKE_CROSSCOMPILING)
    set_tests_properties(python_web_tls PROPERTIES LABELS host_only)
  endif()
endif()

# The page's chessboard-pair helper: captures refused without a login, full-size pairs written,
# listed and downloaded, names outside the folder refused, no record_dir said.
if(TARGET stereohash-fw-sim)
  add_test(NAME python_web_calibration
           COMMAND /usr/bin/python3 ${CMAKE_CURRENT_LIST_DIR}/test_web_calibration.py
                   --firmware $<TARGET_FILE:stereohash-fw-sim>)
  set_tests_properties(python_web_calibration PROPERTIES TIMEOUT 300)
  if(CMAKE_CROSSCOMPILING)
    set_tests_properties(python_web_calibration PROPERTIES LABELS host_only)
  endif()
endif()
