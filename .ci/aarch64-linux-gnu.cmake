# Cross build for ARM64 (.ci/run's aarch64 part): Debian's aarch64 GCC (g++-aarch64-linux-gnu),
# the programs and tests run under qemu-user (qemu-aarch64), which ctest puts before each test
# binary. The header-only dependencies (Eigen, Catch2 2, nlohmann_json) come from the host's
# /usr; libraries (OpenMP's libgomp, the C++ runtime) from the cross toolchain's
# /usr/aarch64-linux-gnu. No -march=native here: the cross compiler cannot see its target, and
# CMakeLists.txt's check falls back to the compiler's default (armv8-a with NEON).
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
set(CMAKE_FIND_ROOT_PATH /usr/aarch64-linux-gnu)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE BOTH)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE BOTH)
set(CMAKE_CROSSCOMPILING_EMULATOR qemu-aarch64 -L /usr/aarch64-linux-gnu)
