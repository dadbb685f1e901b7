# The install layout (GNUInstallDirs) and share/bims, the run-time files
# programs find next to themselves (bims::findShareFile,
# libs/common/include/bims/common/share.h). Included by the top-level
# CMakeLists.txt before the libraries; bims_install_package() at its end.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

# share/bims as seen from a program's folder (bin/), in an install prefix
# and in the build tree alike: build/bin -> build/share/bims. The installed
# folder itself is compiled in as the fallback.
set(BIMS_SHARE_FROM_BIN "../share/bims")
set(BIMS_INSTALL_SHARE_DIR "${CMAKE_INSTALL_FULL_DATADIR}/bims")
get_filename_component(BIMS_BUILD_SHARE_DIR
  "${CMAKE_RUNTIME_OUTPUT_DIRECTORY}/${BIMS_SHARE_FROM_BIN}" ABSOLUTE)
# Made afresh at each configure (no links to files since removed).
file(REMOVE_RECURSE "${BIMS_BUILD_SHARE_DIR}")

# bims_share(FILES ... [SUBDIR sub]): files of share/bims[/sub]. Installed
# into DATADIR/bims[/sub], and linked into the build tree's share/bims[/sub]
# (symbolic links: an edit of the source file is seen at once).
function(bims_share)
  cmake_parse_arguments(A "" "SUBDIR" "FILES" ${ARGN})
  set(build_dir "${BIMS_BUILD_SHARE_DIR}")
  set(install_dir "${CMAKE_INSTALL_DATADIR}/bims")
  if(A_SUBDIR)
    string(APPEND build_dir "/${A_SUBDIR}")
    string(APPEND install_dir "/${A_SUBDIR}")
  endif()
  file(MAKE_DIRECTORY "${build_dir}")
  foreach(f ${A_FILES})
    get_filename_component(name "${f}" NAME)
    file(CREATE_LINK "${f}" "${build_dir}/${name}" SYMBOLIC)
  endforeach()
  install(FILES ${A_FILES} DESTINATION "${install_dir}")
endfunction()

# bims_install_package(): the CMake package of the installed libraries
# (find_package(bims) -> bims::common, bims::maps, bims::pipeline, ...):
# the exported targets, bimsConfig.cmake (finds the dependencies again) and
# its version file, in LIBDIR/cmake/bims. Paths in them are relative to the
# prefix: an installed tree can be moved.
function(bims_install_package)
  set(cmake_dir "${CMAKE_INSTALL_LIBDIR}/cmake/bims")
  install(EXPORT bimsTargets NAMESPACE bims:: DESTINATION "${cmake_dir}")
  configure_package_config_file(
    "${PROJECT_SOURCE_DIR}/cmake/bimsConfig.cmake.in"
    "${PROJECT_BINARY_DIR}/bimsConfig.cmake"
    INSTALL_DESTINATION "${cmake_dir}"
    NO_SET_AND_CHECK_MACRO)
  write_basic_package_version_file(
    "${PROJECT_BINARY_DIR}/bimsConfigVersion.cmake"
    VERSION ${PROJECT_VERSION}
    COMPATIBILITY SameMinorVersion)
  install(FILES "${PROJECT_BINARY_DIR}/bimsConfig.cmake"
                "${PROJECT_BINARY_DIR}/bimsConfigVersion.cmake"
          DESTINATION "${cmake_dir}")
endfunction()
