# Shared CMake helpers for bims targets. Nothing here edits global flags.

# Warnings and language level for one of our targets. No contraction of
# a * b + c into a fused multiply-add: the results (and the tests that hold
# SIMD and scalar paths to the same bits) do not depend on whether the
# compiler may use FMA (e.g. -march=native on a CPU that has it).
function(bims_target_defaults tgt)
  target_compile_features(${tgt} PUBLIC cxx_std_17)
  target_compile_options(${tgt} PRIVATE -Wall -Wextra -ffp-contract=off
                                        $<$<BOOL:${BIMS_WERROR}>:-Werror>)
endfunction()

# bims_exclude_if_untested(target label...): TARGET is left out of the
# default build when the tests of every LABEL are (BIMS_SKIP_TEST_LABELS):
# such a tree builds what its suite runs, e.g. the sanitizer tree of make
# test-sanitize (no cli and sweep tests) builds neither bims-sweep nor
# bims-maps-figure and the two flow tools. Without LABELs, nothing is left out.
function(bims_exclude_if_untested tgt)
  if(NOT ARGN)
    return()
  endif()
  foreach(label ${ARGN})
    if(NOT label IN_LIST BIMS_SKIP_TEST_LABELS)
      return()
    endif()
  endforeach()
  set_target_properties(${tgt} PROPERTIES EXCLUDE_FROM_ALL ON)
endfunction()

# bims_add_library(NAME sim SOURCES ... DEPS ... [NO_INSTALL] [TESTED_BY label...])
# Creates static library bims_<NAME> with alias bims::<NAME>; public headers in
# libs/<NAME>/include/bims/<NAME>/. Unless NO_INSTALL, the library joins the
# exported package (bims::<NAME> for find_package(bims), cmake/BimsInstall.cmake)
# and its headers are installed into include/bims/<NAME>/.
function(bims_add_library)
  cmake_parse_arguments(A "NO_INSTALL" "NAME" "SOURCES;DEPS;PRIVATE_DEPS;TESTED_BY" ${ARGN})
  set(tgt bims_${A_NAME})
  add_library(${tgt} STATIC ${A_SOURCES})
  add_library(bims::${A_NAME} ALIAS ${tgt})
  target_include_directories(${tgt} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_link_libraries(${tgt} PUBLIC ${A_DEPS} PRIVATE ${A_PRIVATE_DEPS})
  set_target_properties(${tgt} PROPERTIES POSITION_INDEPENDENT_CODE ON
                                          EXPORT_NAME ${A_NAME})
  bims_target_defaults(${tgt})
  bims_exclude_if_untested(${tgt} ${A_TESTED_BY})
  if(NOT A_NO_INSTALL)
    install(TARGETS ${tgt} EXPORT bimsTargets
            ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
    install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/include/
            DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  endif()
endfunction()

# bims_add_app(NAME bims-sim SOURCES ... DEPS ... [SUMMARY "one line"]
# [TESTED_BY label...]): an executable in build/bin, and its man page
# (bims_add_man_page). TESTED_BY: the labels of the only tests that run it
# (bims_exclude_if_untested).
function(bims_add_app)
  cmake_parse_arguments(A "" "NAME;SUMMARY" "SOURCES;DEPS;TESTED_BY" ${ARGN})
  add_executable(${A_NAME} ${A_SOURCES})
  target_link_libraries(${A_NAME} PRIVATE ${A_DEPS})
  bims_target_defaults(${A_NAME})
  bims_exclude_if_untested(${A_NAME} ${A_TESTED_BY})
  install(TARGETS ${A_NAME} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  bims_add_man_page(${A_NAME} "${A_SUMMARY}")
endfunction()

# The programs' man pages, made at build time from their --help by Debian's
# help2man (scripts/install-deps.sh installs it), into build/share/man/man1
# (BIMS_MAN_DIR) and installed into MANDIR/man1. Without help2man, or in a
# sanitizer build (the programs would run under the sanitizers at build
# time), there are none, with a status message.
find_program(BIMS_HELP2MAN help2man)
if(BIMS_HELP2MAN AND NOT BIMS_SANITIZE)
  set(BIMS_MAN_DIR "${PROJECT_BINARY_DIR}/share/man/man1")
  file(MAKE_DIRECTORY "${BIMS_MAN_DIR}")
  # Every page's FILES (share/bims) and SEE ALSO (the other programs):
  # docs/man/common.h2m.in; each program's EXAMPLES: docs/man/PROGRAM.h2m.
  set(BIMS_MAN_SOURCE_DIR "${PROJECT_SOURCE_DIR}/docs/man")
  file(GLOB _bims_man_includes "${BIMS_MAN_SOURCE_DIR}/bims-*.h2m")
  set(BIMS_MAN_SEE_ALSO "")
  foreach(_inc IN LISTS _bims_man_includes)
    get_filename_component(_prog "${_inc}" NAME_WE)
    string(REPLACE "-" "\\-" _prog "${_prog}")
    list(APPEND BIMS_MAN_SEE_ALSO "\\fB${_prog}\\fR(1)")
  endforeach()
  list(JOIN BIMS_MAN_SEE_ALSO ", " BIMS_MAN_SEE_ALSO)
  set(BIMS_MAN_DATADIR "${CMAKE_INSTALL_FULL_DATADIR}")
  configure_file("${BIMS_MAN_SOURCE_DIR}/common.h2m.in"
                 "${PROJECT_BINARY_DIR}/share/man/common.h2m" @ONLY)
else()
  set(BIMS_MAN_DIR "")
  message(STATUS "bims: no man pages (help2man not found, or a sanitizer build)")
endif()

# bims_add_man_page(program "summary"): PROGRAM.1 from `program --help`
# (target PROGRAM-man, part of the default build).
function(bims_add_man_page program summary)
  get_target_property(left_out ${program} EXCLUDE_FROM_ALL)
  if(NOT BIMS_MAN_DIR OR left_out)
    return()
  endif()
  if(NOT summary)
    set(summary "a bims program")
  endif()
  set(page "${BIMS_MAN_DIR}/${program}.1")
  set(common "${PROJECT_BINARY_DIR}/share/man/common.h2m")
  set(examples "${BIMS_MAN_SOURCE_DIR}/${program}.h2m")
  if(NOT EXISTS "${examples}")
    message(FATAL_ERROR "${program}: no docs/man/${program}.h2m (its man "
                        "page's EXAMPLES)")
  endif()
  # run by its name (PATH), so that the page's usage line has no build path
  add_custom_command(OUTPUT "${page}"
    COMMAND ${CMAKE_COMMAND} -E env
            "PATH=$<TARGET_FILE_DIR:${program}>:$ENV{PATH}"
            "${BIMS_HELP2MAN}" --no-info --no-discard-stderr
            "--version-string=${PROJECT_VERSION}" "--name=${summary}"
            "--include=${examples}" "--include=${common}"
            "--output=${page}" ${program}
    DEPENDS ${program} "${examples}" "${common}"
    COMMENT "man page ${program}.1 (help2man)"
    VERBATIM)
  add_custom_target(${program}-man ALL DEPENDS "${page}")
  install(FILES "${page}" DESTINATION "${CMAKE_INSTALL_MANDIR}/man1")
endfunction()

# bims_add_gtest(NAME test_x SOURCES ... DEPS ... [LABELS ...] [TIMEOUT s])
# (none when one of its LABELS is in BIMS_SKIP_TEST_LABELS)
# A gtest executable in build/bin, its cases registered with CTest one by one;
# with BIMS_TEST_SHARDS=N > 0, as N CTest tests test_x/K-of-N instead, each
# running every N-th case in one process (GoogleTest's sharding: the
# sanitizer tree, where starting a process costs ~0.9 s; GTEST_FILTER in
# the environment then leaves cases out).
# Compile definitions give the tests the source tree, the shared data folder and
# the binary folder (where the apps are).
function(bims_add_gtest)
  cmake_parse_arguments(A "" "NAME;TIMEOUT" "SOURCES;DEPS;LABELS" ${ARGN})
  if(NOT BIMS_BUILD_TESTS)
    return()
  endif()
  foreach(label ${A_LABELS})
    if(label IN_LIST BIMS_SKIP_TEST_LABELS)
      return()
    endif()
  endforeach()
  if(NOT A_TIMEOUT)
    set(A_TIMEOUT 300)
  endif()
  if(BIMS_SANITIZE)  # the sanitizer suite runs 3-10x slower
    math(EXPR A_TIMEOUT "${A_TIMEOUT} * 5")
  endif()
  add_executable(${A_NAME} ${A_SOURCES})
  target_link_libraries(${A_NAME} PRIVATE ${A_DEPS} GTest::gtest GTest::gtest_main)
  target_compile_definitions(${A_NAME} PRIVATE
    BIMS_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
    BIMS_BINARY_DIR="${PROJECT_BINARY_DIR}"
    BIMS_BIN_DIR="${CMAKE_RUNTIME_OUTPUT_DIRECTORY}"
    BIMS_SHARED_DATA_DIR="${BIMS_SHARED_DATA_DIR}")
  # helpers shared by the tests (bims_test/...)
  target_include_directories(${A_NAME} PRIVATE ${PROJECT_SOURCE_DIR}/tests/support)
  bims_target_defaults(${A_NAME})
  # Each build tree's tests keep their scratch folders in the tree
  # (TMPDIR), so that two trees tested at once never share a folder.
  set(test_tmp "${PROJECT_BINARY_DIR}/test-tmp")
  file(MAKE_DIRECTORY "${test_tmp}")
  if(BIMS_TEST_SHARDS GREATER 0)
    # A shard runs many cases: the time of the longest ones together.
    math(EXPR A_TIMEOUT "${A_TIMEOUT} * 4")
    foreach(k RANGE 1 ${BIMS_TEST_SHARDS})
      math(EXPR index "${k} - 1")
      set(shard "${A_NAME}/${k}-of-${BIMS_TEST_SHARDS}")
      add_test(NAME ${shard} COMMAND ${A_NAME}
               WORKING_DIRECTORY ${PROJECT_BINARY_DIR})
      set_tests_properties(${shard} PROPERTIES
        TIMEOUT ${A_TIMEOUT} LABELS "${A_LABELS}"
        ENVIRONMENT "GTEST_TOTAL_SHARDS=${BIMS_TEST_SHARDS};GTEST_SHARD_INDEX=${index};TMPDIR=${test_tmp}")
    endforeach()
    return()
  endif()
  gtest_discover_tests(${A_NAME}
    DISCOVERY_MODE PRE_TEST
    WORKING_DIRECTORY ${PROJECT_BINARY_DIR}
    PROPERTIES TIMEOUT ${A_TIMEOUT} ENVIRONMENT "TMPDIR=${test_tmp}"
               LABELS "${A_LABELS}")
endfunction()

# bims_write_module_graph(FILE): one line per library module, "module: the
# bims modules it links directly" (PUBLIC, PRIVATE and INTERFACE links, the
# targets' own LINK_LIBRARIES), for scripts/check_layers.py (test
# Architecture.IncludesFollowTheLinks): the graph the build really has, not a
# copy of it.
function(bims_write_module_graph file)
  set(text "")
  foreach(module ${ARGN})
    if(NOT TARGET bims_${module})
      continue()
    endif()
    get_target_property(type bims_${module} TYPE)
    set(links "")
    foreach(prop LINK_LIBRARIES INTERFACE_LINK_LIBRARIES)
      if(type STREQUAL "INTERFACE_LIBRARY" AND prop STREQUAL "LINK_LIBRARIES")
        continue()
      endif()
      get_target_property(l bims_${module} ${prop})
      if(l)
        list(APPEND links ${l})
      endif()
    endforeach()
    string(REGEX MATCHALL "bims(::|_)[a-z_]+" deps "${links}")
    list(TRANSFORM deps REPLACE "^bims(::|_)" "")
    list(REMOVE_ITEM deps rosbag_deps)
    list(REMOVE_DUPLICATES deps)
    list(REMOVE_ITEM deps ${module})
    list(JOIN deps " " deps)
    string(APPEND text "${module}: ${deps}\n")
  endforeach()
  file(WRITE ${file} "${text}")
endfunction()
