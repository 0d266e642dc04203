# GPIO: interface + simulator everywhere; the libgpiod backend only where libgpiod was found by
# pkg-config (top-level CMakeLists; for cross builds PKG_CONFIG_LIBDIR points at the arm64 .pc).
find_package(Threads REQUIRED)

stereohash_module(stereohash_hal_gpio
  SOURCES gpio_common.cpp
  HEADERS gpio.hpp
  PUBLIC stereohash_base)

stereohash_module(stereohash_hal_gpio_sim
  SOURCES sim/gpio_sim.cpp
  HEADERS sim/gpio_sim.hpp
  PUBLIC stereohash_hal_gpio Threads::Threads)

if(LIBGPIOD_FOUND AND TARGET PkgConfig::LIBGPIOD)
  stereohash_module(stereohash_hal_gpiod
    SOURCES linux/gpiod_gpio.cpp
    HEADERS linux/gpiod_gpio.hpp
    PUBLIC stereohash_hal_gpio PkgConfig::LIBGPIOD)
else()
  message(STATUS "libgpiod not found: the Linux GPIO backend (stereohash_hal_gpiod) is not built")
endif()
