# Stereo capture: interface + pairing (host-testable), simulator backends, libcamera backend.
find_package(Threads REQUIRED)

add_library(stereohash_hal_camera STATIC ${CMAKE_CURRENT_LIST_DIR}/stereo_pairing.cpp)
target_link_libraries(stereohash_hal_camera PUBLIC stereohash_base Threads::Threads)

