# A python test of the page against the simulator (host only when cross-compiling; 77 = skipped).
function(stereohash_python_web_test name script)
  if(NOT TARGET stereohash-fw-sim)
    return()
  endif()
  add_test(NAME ${name}
           COMMAND /usr/bin/python3 ${CMAKE_CURRENT_FUNCTION_LIST_DIR}/${script}
                   --firmware $<TARGET_FILE:stereohash-fw-sim>)
  set_tests_properties(${name} PROPERTIES TIMEOUT 300 SKIP_RETURN_CODE 77)
  if(CMAKE_CROSSCOMPILING)
    set_tests_properties(${name} PROPERTIES LABELS host_only)
  endif()
endfunction()

# The commissioning web page under hostile clients (many connections, slowloris, oversized
# requests, path traversal, writes without a login, a request flood) while a PLC triggers over
# CAN: every trigger answered, heartbeats in every phase, nothing written.
stereohash_python_web_test(python_web_hostile test_web_hostile.py)
# The page over HTTPS: served, logged into (Secure cookie), plain HTTP refused on its port; a key
# of another certificate refused at start while the node keeps its heartbeat.
stereohash_python_web_test(python_web_tls test_web_tls.py)
# The page's chessboard-pair helper: captures refused without a login, full-size pairs written,
# listed and downloaded, names outside the folder refused, no record_dir said.
stereohash_python_web_test(python_web_calibration test_web_calibration.py)
