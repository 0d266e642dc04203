# GPIO: interface + simulator everywhere; the libgpiod backend only where libgpiod was found by
# pkg-config (top-level CMakeLists; for cross builds PKG_CONFIG_LIBDIR points at the arm64 .pc).
find_package(Threads REQUIRED)

add_library(stereohash_hal_gpio STATIC ${CMAKE_CURRENT_SOURCE_DIR}/gpio_common.cpp)
target_link_libraries(stereohash_hal_gpio PUBLIC stereohash_base)

add_library(stereohash_hal_gpio_sim STATIC ${CMAKE_CURRENT_SOURCE_DIR}/sim/gpio_sim.cpp)
target_link_libraries(stereohash_hal_gpio_sim PUBLIC stereohash_hal_gpio Threads::Threads)

if(LIBGPIOD_FOUND AND TARGET PkgConfig::LIBGPIOD)
  add_library(stereohash_hal_gpiod STATIC ${CMAKE_CURRENT_SOURCE_DIR}/linux/gpiod_gpio.cpp)
  target_link_libraries(stereohash_hal_gpiod PUBLIC stereohash_hal_gpio PkgConfig::LIBGPIOD)
else()
  message(STATUS "libgpiod not found: the Linux GPIO backend (stereohash_hal_gpiod) is not built")
endif()
