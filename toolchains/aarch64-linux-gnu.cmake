# Cross build for the aarch64 Linux vision board with Debian's g++-aarch64-linux-gnu and arm64
# multiarch -dev packages (libcamera-dev:arm64, libgpiod-dev:arm64, libgtest-dev:arm64).
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
set(CMAKE_ASM_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)

# Multiarch: target libraries live beside the host ones under /usr/lib/aarch64-linux-gnu, headers
# are shared in /usr/include. Search programs on the host, libraries for the target.
set(CMAKE_FIND_ROOT_PATH /usr/aarch64-linux-gnu)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(ENV{PKG_CONFIG_LIBDIR} /usr/lib/aarch64-linux-gnu/pkgconfig:/usr/share/pkgconfig)

# No binfmt_misc on build machines: CTest and build-time generators run target binaries here.
set(CMAKE_CROSSCOMPILING_EMULATOR qemu-aarch64;-L;/)
