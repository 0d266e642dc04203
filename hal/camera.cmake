# Stereo capture: interface + pairing (host-testable), simulator backends, libcamera backend.
find_package(Threads REQUIRED)

add_library(stereohash_hal_camera STATIC ${CMAKE_CURRENT_LIST_DIR}/stereo_pairing.cpp)
target_link_libraries(stereohash_hal_camera PUBLIC stereohash_base Threads::Threads)

add_library(stereohash_hal_camera_sim STATIC
  ${CMAKE_CURRENT_LIST_DIR}/sim/sim_camera.cpp
  ${CMAKE_CURRENT_LIST_DIR}/sim/directory_camera.cpp)
# stereohash_image_files (PNG/PGM decoding) is defined in hal/render.cmake.
target_link_libraries(stereohash_hal_camera_sim PUBLIC stereohash_hal_camera stereohash_image_files)

# The board backend builds wherever libcamera's pkg-config file is found (native or aarch64).
if(LIBCAMERA_FOUND)
  add_library(stereohash_hal_camera_libcamera STATIC
    ${CMAKE_CURRENT_LIST_DIR}/linux/libcamera_camera.cpp
    ${CMAKE_CURRENT_LIST_DIR}/linux/libcamera_adapter.cpp)
  target_link_libraries(stereohash_hal_camera_libcamera
                        PUBLIC stereohash_hal_camera PRIVATE PkgConfig::LIBCAMERA)
endif()
