# The installed package, in steps run by CTest (tests/CMakeLists.txt):
#   cmake -DSTEP=install|consumer|viewer -DBUILD_DIR=... -DSOURCE_DIR=...
#         -DWORK_DIR=... -DLIBDIR=... [-DGENERATOR=... -DCXX_COMPILER=...
#         -DCXX_LAUNCHER=... -DSANITIZE=...] -P package_test.cmake
# install:  cmake --install BUILD_DIR into WORK_DIR/staged; every part there
#           (programs, headers, libraries, CMake package, share/bims), no
#           path of the build or source tree in the package files; then the
#           tree is moved to WORK_DIR/prefix (it must work from there).
# consumer: tests/package_consumer configured with find_package(bims)
#           against WORK_DIR/prefix, built and run: a grid from an .ini
#           (bims::maps), a pipeline from share/bims/default.ini.
# viewer:   the moved tree's bims-viewer finds its share/bims/default.ini.
# python:   the Python tests (libs/python/tests) with the moved prefix's
#           package and programs (-DPYTHON=... -DPYTHON_DIR=...).
cmake_minimum_required(VERSION 3.16)

foreach(v STEP BUILD_DIR SOURCE_DIR WORK_DIR LIBDIR)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "package_test.cmake: -D${v}=... missing")
  endif()
endforeach()
set(staged "${WORK_DIR}/staged")
set(prefix "${WORK_DIR}/prefix")

# run(<what> COMMAND ...): the command's output in OUT, a failure names it
macro(run what)
  execute_process(${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE OUT
                  ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} failed (${rc}):\n${OUT}\n${err}")
  endif()
endmacro()

if(STEP STREQUAL "install")
  file(REMOVE_RECURSE "${WORK_DIR}")
  run("cmake --install" COMMAND "${CMAKE_COMMAND}" --install "${BUILD_DIR}"
      --prefix "${staged}")
  foreach(f bin/bims-run bin/bims-sim
            include/bims/common/share.h include/bims/maps/COccupancyBayesGrid.h
            include/bims/pipeline/pipeline.h
            ${LIBDIR}/libbims_common.a ${LIBDIR}/libbims_maps_core.a
            ${LIBDIR}/libbims_pipeline.a
            ${LIBDIR}/cmake/bims/bimsConfig.cmake
            ${LIBDIR}/cmake/bims/bimsConfigVersion.cmake
            ${LIBDIR}/cmake/bims/bimsTargets.cmake
            share/bims/default.ini share/bims/bonn.ini
            share/bims/sim/crowded.ini share/bims/README.md)
    if(NOT EXISTS "${staged}/${f}")
      message(FATAL_ERROR "not installed: ${f}")
    endif()
    if(IS_SYMLINK "${staged}/${f}")
      message(FATAL_ERROR "installed as a link (into the build?): ${f}")
    endif()
  endforeach()
  # Relocatable: the package files name no folder of this build.
  file(GLOB pkg_files "${staged}/${LIBDIR}/cmake/bims/*.cmake")
  foreach(f ${pkg_files})
    file(READ "${f}" text)
    foreach(dir "${BUILD_DIR}" "${SOURCE_DIR}" "${WORK_DIR}")
      string(FIND "${text}" "${dir}" at)
      if(NOT at EQUAL -1)
        message(FATAL_ERROR "${f} names the folder ${dir}: not relocatable")
      endif()
    endforeach()
  endforeach()
  file(RENAME "${staged}" "${prefix}")
  message(STATUS "installed, then moved to ${prefix}")

elseif(STEP STREQUAL "consumer")
  set(src "${SOURCE_DIR}/tests/package_consumer")
  set(bld "${WORK_DIR}/consumer")
  file(REMOVE_RECURSE "${bld}")
  set(args -S "${src}" -B "${bld}" -DCMAKE_BUILD_TYPE=Release
      "-DCMAKE_PREFIX_PATH=${prefix}")
  if(GENERATOR)
    list(APPEND args -G "${GENERATOR}")
  endif()
  if(CXX_COMPILER)
    list(APPEND args "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}")
  endif()
  if(CXX_LAUNCHER)
    list(APPEND args "-DCMAKE_CXX_COMPILER_LAUNCHER=${CXX_LAUNCHER}")
  endif()
  if(SANITIZE)  # the libraries were built with them (make test-sanitize)
    list(APPEND args "-DCMAKE_CXX_FLAGS=-fsanitize=${SANITIZE}"
                     "-DCMAKE_EXE_LINKER_FLAGS=-fsanitize=${SANITIZE}")
  endif()
  run("configuring the consumer" COMMAND "${CMAKE_COMMAND}" ${args})
  # the package of the moved tree, not another one
  file(STRINGS "${bld}/CMakeCache.txt" bims_dir REGEX "^bims_DIR:")
  if(NOT bims_dir MATCHES "=${prefix}/")
    message(FATAL_ERROR "the consumer found another bims: ${bims_dir}")
  endif()
  run("building the consumer" COMMAND "${CMAKE_COMMAND}" --build "${bld}")
  run("running the consumer" COMMAND "${bld}/grid_from_ini" "${src}/grid.ini")
  if(NOT OUT MATCHES "bims::maps::COccupancyBayesGrid: [1-9][0-9]* occupied voxels")
    message(FATAL_ERROR "unexpected output of the consumer:\n${OUT}")
  endif()
  message(STATUS "${OUT}")
  # the pipeline, with the moved tree's default parameters
  run("running the pipeline consumer" COMMAND "${bld}/pipeline_from_ini"
      "${prefix}/share/bims/default.ini")
  if(NOT OUT MATCHES "pipeline from .*/share/bims/default.ini: voxel size")
    message(FATAL_ERROR "unexpected output of the consumer:\n${OUT}")
  endif()
  message(STATUS "${OUT}")

elseif(STEP STREQUAL "python")
  # The Python tests against the moved prefix: its package, its bims-run.
  foreach(v PYTHON PYTHON_DIR)
    if(NOT DEFINED ${v})
      message(FATAL_ERROR "package_test.cmake: -D${v}=... missing")
    endif()
  endforeach()
  set(site "${prefix}/${PYTHON_DIR}")
  foreach(f __init__.py _bims.pyi py.typed)
    if(NOT EXISTS "${site}/bims/${f}")
      message(FATAL_ERROR "not installed: ${PYTHON_DIR}/bims/${f}")
    endif()
  endforeach()
  run("the Python tests against ${site}"
      COMMAND "${CMAKE_COMMAND}" -E env "PYTHONPATH=${site}"
              "BIMS_SOURCE_DIR=${SOURCE_DIR}" "BIMS_BIN_DIR=${prefix}/bin"
              "BIMS_EXPECT_PACKAGE_DIR=${site}/bims"
              "${PYTHON}" -m unittest discover
              -s "${SOURCE_DIR}/libs/python/tests" -p "test_*.py")
elseif(STEP STREQUAL "viewer")
  # No display: the viewer says which parameters it uses, then fails to
  # open its window (the exit code is not the point here).
  execute_process(
    COMMAND "${CMAKE_COMMAND}" -E env --unset=DISPLAY --unset=WAYLAND_DISPLAY
            "${prefix}/bin/bims-viewer"
    OUTPUT_VARIABLE out ERROR_VARIABLE err)
  file(REAL_PATH "${prefix}/share/bims/default.ini" expected)
  string(FIND "${out}${err}" "bims-viewer: parameters from ${expected}\n" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "the moved bims-viewer did not use ${expected}:\n"
                        "${out}${err}")
  endif()

else()
  message(FATAL_ERROR "package_test.cmake: unknown STEP '${STEP}'")
endif()
