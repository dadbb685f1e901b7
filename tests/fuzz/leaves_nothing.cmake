# Runs one corpus replay with TMPDIR set to an empty folder of its own and
# fails unless the folder is empty again afterwards (the replay's scratch
# files are removed at exit, not left in TMPDIR after every run).
#   cmake -DREPLAY=<program> -DCORPUS=<folder> -DTMP=<folder> -P leaves_nothing.cmake
file(REMOVE_RECURSE "${TMP}")
file(MAKE_DIRECTORY "${TMP}")
execute_process(COMMAND ${CMAKE_COMMAND} -E env TMPDIR=${TMP} ${REPLAY} ${CORPUS}
                RESULT_VARIABLE rc OUTPUT_QUIET)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${REPLAY} failed (${rc})")
endif()
file(GLOB left "${TMP}/*")
if(left)
  message(FATAL_ERROR "${REPLAY} left files in TMPDIR: ${left}")
endif()
file(REMOVE_RECURSE "${TMP}")
