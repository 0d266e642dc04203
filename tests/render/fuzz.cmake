# libFuzzer targets for the image decoders (configure with clang and -DSTEREOHASH_FUZZ=ON).
# Run: build/.../tests/render/png_fuzz -max_total_time=60 tests/fuzz/corpus/png
foreach(target png_fuzz pgm_fuzz)
  if(NOT TARGET ${target})
    add_executable(${target} ${PROJECT_SOURCE_DIR}/tests/fuzz/${target}.cpp
                   ${PROJECT_SOURCE_DIR}/hal/sim/image_files.cpp
                   ${PROJECT_SOURCE_DIR}/hal/sim/inflate.cpp
                   ${PROJECT_SOURCE_DIR}/hal/sim/deflate.cpp
                   ${PROJECT_SOURCE_DIR}/recog/base/crc32.cpp
                   ${PROJECT_SOURCE_DIR}/recog/base/status.cpp)
    target_compile_options(${target} PRIVATE -g -fsanitize=fuzzer,address,undefined)
    target_link_options(${target} PRIVATE -fsanitize=fuzzer,address,undefined)
  endif()
endforeach()
