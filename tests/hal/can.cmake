# CAN HAL and PLC protocol tests.
stereohash_add_test(can_hal_test THREADS
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/can_log_test.cpp ${CMAKE_CURRENT_LIST_DIR}/can_sim_bus_test.cpp
          ${CMAKE_CURRENT_LIST_DIR}/socketcand_test.cpp
  LIBS stereohash_hal_can_sim)
stereohash_add_test(socketcan_test PER_CASE SOURCES ${CMAKE_CURRENT_LIST_DIR}/socketcan_test.cpp
  LIBS stereohash_hal_socketcan)
stereohash_add_test(can_protocol_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/can_protocol_test.cpp
  LIBS stereohash_can_protocol stereohash_result_assembler)

# Stand-in device for the Python end-to-end test: sim bus + socketcand server + protocol.
add_executable(can_sim_demo ${CMAKE_CURRENT_LIST_DIR}/can_sim_demo.cpp)
target_link_libraries(can_sim_demo PRIVATE stereohash_hal_can_sim stereohash_can_protocol
                      stereohash_warnings)

if(benchmark_FOUND)
  add_executable(can_bench ${CMAKE_CURRENT_LIST_DIR}/can_bench.cpp)
  target_link_libraries(can_bench PRIVATE stereohash_can_protocol stereohash_result_assembler
                        stereohash_hal_can_sim
                        benchmark::benchmark stereohash_warnings)
endif()
