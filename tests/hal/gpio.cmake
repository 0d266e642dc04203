# GPIO HAL tests; the libgpiod part only where the backend is built.
set(_gpio_libs stereohash_hal_gpio_sim)
if(TARGET stereohash_hal_gpiod)
  list(APPEND _gpio_libs stereohash_hal_gpiod)
endif()
stereohash_add_test(gpio_test THREADS PER_CASE SOURCES ${CMAKE_CURRENT_LIST_DIR}/gpio_test.cpp LIBS ${_gpio_libs})
if(TARGET stereohash_hal_gpiod)
  target_compile_definitions(gpio_test PRIVATE STEREOHASH_HAVE_GPIOD=1)
endif()
