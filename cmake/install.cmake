# The library as a package (docs/library.md): `cmake --install` puts the public headers, the
# library's static archives and a package config under the prefix, so that another project writes
#   find_package(femcourse 1.0 CONFIG REQUIRED)
#   target_link_libraries(app PRIVATE femcourse::simulator)
# and reads gmsh's .msh files with it (body_from_gmsh_file: the course's own reader, no gmsh
# SDK). The same names work after add_subdirectory (the aliases below).
#
# What the package holds, and what it passes to a consumer:
#  - headers: femcourse/simulator.hpp only (the public API; it compiles alone, with the standard
#    library only: tests/library/installed_package.sh). The course's own headers (common/,
#    chapters/, and the library's own femcourse/node_forces.hpp) are the advanced API of a build
#    inside the source tree (add_subdirectory).
#  - archives: fem_simulator, fem_steppers (the chapters' steppers, no lesson, report or work
#    code), fem_core (what a stepper needs: no JSON, command line, VTK nor lessons), fem_fallbacks.
#  - usage requirements: the include directory, and the OpenMP runtime to link (libgomp with
#    GCC) as a link-only dependency: no -fopenmp, no -march, no warning flag reaches the
#    consumer's compile line, and the consumer needs no Eigen.
#  - the instruction set the archives were compiled for (FEM_NATIVE: this machine's, else the
#    compiler's default), recorded in the config and checked against the consuming machine at
#    its configure time.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(FEM_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/femcourse)
set(FEM_LIBRARY_TARGETS fem_core fem_steppers fem_simulator fem_fallbacks)
set_target_properties(fem_core PROPERTIES EXPORT_NAME core)
set_target_properties(fem_steppers PROPERTIES EXPORT_NAME steppers)
set_target_properties(fem_simulator PROPERTIES EXPORT_NAME simulator)
set_target_properties(fem_fallbacks PROPERTIES EXPORT_NAME fallbacks)
add_library(femcourse::simulator ALIAS fem_simulator)
# The former gmsh reader's name, for an app written against it: the reader is in the library.
add_library(femcourse::mesh_gmsh ALIAS fem_simulator)
# Installed, `#include <femcourse/simulator.hpp>` finds include/femcourse/simulator.hpp: no
# other name lands on the consumer's include path.
target_include_directories(fem_simulator PUBLIC $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)

# The instruction set: the x86 extensions our compile options enable, by the compiler's own
# predefined macros, as /proc/cpuinfo names them.
set(FEM_ISA_MACROS __AVX512F__ __AVX512BW__ __AVX512VL__ __AVX2__ __FMA__ __BMI2__ __AVX__
                   __SSE4_2__)
set(FEM_ISA_FLAGS avx512f avx512bw avx512vl avx2 fma bmi2 avx sse4_2)
get_directory_property(FEM_ISA_OPTIONS COMPILE_OPTIONS)
separate_arguments(FEM_ISA_CXX_FLAGS UNIX_COMMAND "${CMAKE_CXX_FLAGS}")
execute_process(COMMAND ${CMAKE_CXX_COMPILER} ${FEM_ISA_CXX_FLAGS} ${FEM_ISA_OPTIONS} -dM -E
                        -x c++ /dev/null
                OUTPUT_VARIABLE FEM_PREDEFINED ERROR_QUIET)
set(FEM_PACKAGE_CPU_FLAGS "")
foreach(macro flag IN ZIP_LISTS FEM_ISA_MACROS FEM_ISA_FLAGS)
  if(FEM_PREDEFINED MATCHES "#define ${macro} 1")
    list(APPEND FEM_PACKAGE_CPU_FLAGS ${flag})
  endif()
endforeach()
if(FEM_NATIVE_FLAG)
  set(FEM_PACKAGE_MARCH "${FEM_NATIVE_FLAG} on the machine that built it")
else()
  set(FEM_PACKAGE_MARCH "the compiler's default target (portable)")
endif()
message(STATUS "femcourse package: compiled for ${FEM_PACKAGE_MARCH}: ${FEM_PACKAGE_CPU_FLAGS}")

install(TARGETS ${FEM_LIBRARY_TARGETS} EXPORT femcourse-targets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(FILES femcourse/simulator.hpp DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/femcourse)
install(EXPORT femcourse-targets NAMESPACE femcourse:: DESTINATION ${FEM_INSTALL_CMAKEDIR})
set(FEM_PACKAGE_HAS_OPENMP ${OpenMP_CXX_FOUND})

configure_package_config_file(cmake/femcourse-config.cmake.in
                              ${CMAKE_CURRENT_BINARY_DIR}/femcourse-config.cmake
                              INSTALL_DESTINATION ${FEM_INSTALL_CMAKEDIR})
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/femcourse-config-version.cmake
                                 COMPATIBILITY SameMajorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/femcourse-config.cmake
              ${CMAKE_CURRENT_BINARY_DIR}/femcourse-config-version.cmake
        DESTINATION ${FEM_INSTALL_CMAKEDIR})
install(FILES LICENSE LICENSE-docs DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/femcourse)
