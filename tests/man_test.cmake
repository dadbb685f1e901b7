# Man.PagesHaveExamplesFilesAndSeeAlso: every program's man page (made by
# help2man at build time, cmake/BimsHelpers.cmake) has EXAMPLES, FILES
# naming share/bims and SEE ALSO, and cites no path of the source tree's
# config/ folder (an installed program reads its presets from share/bims).
# Skipped (CTest's SKIP_REGULAR_EXPRESSION on the message) only when the
# build makes no man pages (help2man not installed, or a sanitizer build).
# Arguments: -DMAN_DIR=build/share/man/man1 -DHELP2MAN=path or empty
# -DPROGRAMS=bims-run,bims-eval,...
if(NOT HELP2MAN)
  message("BIMS_SKIP: no man pages in this build (help2man not installed)")
  return()
endif()
string(REPLACE "," ";" PROGRAMS "${PROGRAMS}")
set(failures "")
foreach(prog IN LISTS PROGRAMS)
  set(page "${MAN_DIR}/${prog}.1")
  if(NOT EXISTS "${page}")
    list(APPEND failures "${prog}: no man page ${page}")
    continue()
  endif()
  file(READ "${page}" text)
  foreach(section "EXAMPLES" "FILES" "\"SEE ALSO\"")
    string(FIND "${text}" ".SH ${section}" at)
    if(at EQUAL -1)
      list(APPEND failures "${prog}: no ${section} section")
    endif()
  endforeach()
  string(FIND "${text}" "share/bims" at)
  if(at EQUAL -1)
    list(APPEND failures "${prog}: FILES does not name share/bims")
  endif()
  string(REGEX MATCH "[ (]config/[a-z_/]*" cited "${text}")
  if(cited)
    list(APPEND failures "${prog}: cites the source tree's${cited}")
  endif()
endforeach()
if(failures)
  list(JOIN failures "\n" failures)
  message(FATAL_ERROR "${failures}")
endif()
list(LENGTH PROGRAMS n)
message("${n} man pages with EXAMPLES, FILES and SEE ALSO")
