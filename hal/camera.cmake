# Stereo capture: interface + pairing (host-testable), simulator backends, libcamera backend.
find_package(Threads REQUIRED)

stereohash_module(stereohash_hal_camera
  SOURCES stereo_pairing.cpp
  HEADERS camera.hpp stereo_pairing.hpp
  PUBLIC stereohash_image stereohash_base Threads::Threads)

# The simulator's cameras: frames from a FrameSource (the simulated world, test patterns) and
# recorded pairs from a folder of image files.
stereohash_module(stereohash_hal_camera_sim
  SOURCES sim/sim_camera.cpp sim/directory_camera.cpp
  HEADERS sim/sim_camera.hpp sim/sim_camera_source.hpp sim/directory_camera.hpp
  PUBLIC stereohash_hal_camera stereohash_image stereohash_base
  PRIVATE stereohash_image_files stereohash_input_file)

# The board backend builds wherever libcamera's pkg-config file is found (native or aarch64).
if(LIBCAMERA_FOUND)
  stereohash_module(stereohash_hal_camera_libcamera
    SOURCES linux/libcamera_camera.cpp linux/libcamera_adapter.cpp
    HEADERS linux/libcamera_camera.hpp linux/libcamera_adapter.hpp
    PUBLIC stereohash_hal_camera stereohash_image
    PRIVATE PkgConfig::LIBCAMERA)
endif()
