# The library as a package (docs/library.md): `cmake --install` puts the headers, the static
# libraries and a package config under the prefix, so that another project writes
#   find_package(femcourse 1.0 CONFIG REQUIRED)
#   target_link_libraries(app PRIVATE femcourse::simulator)
# and, to read gmsh files, find_package(femcourse CONFIG REQUIRED COMPONENTS mesh_gmsh) and
# femcourse::mesh_gmsh. The same names work after add_subdirectory (the aliases below).
# The installed package needs Eigen and OpenMP (usage requirements of the headers and of the
# threaded chapters), not gmsh, Catch2, Python nor this source tree. Compile options of this
# project (-Wall, -march=native) are directory options, not usage requirements: a consumer
# gets none of them.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(FEM_INSTALL_INCLUDEDIR ${CMAKE_INSTALL_INCLUDEDIR}/femcourse)
set(FEM_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/femcourse)
set(FEM_LIBRARY_TARGETS fem_common fem_chapters fem_simulator fem_fallbacks)
set_target_properties(fem_common PROPERTIES EXPORT_NAME common)
set_target_properties(fem_chapters PROPERTIES EXPORT_NAME chapters)
set_target_properties(fem_simulator PROPERTIES EXPORT_NAME simulator)
set_target_properties(fem_fallbacks PROPERTIES EXPORT_NAME fallbacks)
add_library(femcourse::simulator ALIAS fem_simulator)
if(TARGET fem_mesh_gmsh)
  set_target_properties(fem_mesh_gmsh PROPERTIES EXPORT_NAME mesh_gmsh)
  add_library(femcourse::mesh_gmsh ALIAS fem_mesh_gmsh)
endif()
# Inside the build tree the headers are found from the repository's root; installed, from
# include/femcourse, so that `#include <femcourse/simulator.hpp>` and the chapters'
# `#include "common/..."` both resolve.
target_include_directories(fem_simulator PUBLIC $<INSTALL_INTERFACE:${FEM_INSTALL_INCLUDEDIR}>)

install(TARGETS ${FEM_LIBRARY_TARGETS} EXPORT femcourse-targets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(DIRECTORY common chapters femcourse DESTINATION ${FEM_INSTALL_INCLUDEDIR}
        FILES_MATCHING PATTERN "*.hpp" PATTERN "json.hpp" EXCLUDE)
install(EXPORT femcourse-targets NAMESPACE femcourse:: DESTINATION ${FEM_INSTALL_CMAKEDIR})
if(TARGET fem_mesh_gmsh)
  install(TARGETS fem_mesh_gmsh EXPORT femcourse-mesh-gmsh-targets
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
  install(EXPORT femcourse-mesh-gmsh-targets NAMESPACE femcourse::
          DESTINATION ${FEM_INSTALL_CMAKEDIR})
  set(FEM_PACKAGE_HAS_GMSH ON)
else()
  set(FEM_PACKAGE_HAS_GMSH OFF)
endif()
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
