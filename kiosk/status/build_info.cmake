# Writes OUTPUT, the definition of basalt::kiosk::buildInfo(): VERSION, the revision and BUILD.
# Run at every build (kiosk/status/CMakeLists.txt); the file is rewritten only when what it says
# changes, so a new commit recompiles one small file and an unchanged tree nothing.
# REVISION, when given (a package built from a tarball), is used instead of asking git.
if(NOT REVISION)
  execute_process(COMMAND git -C "${SOURCE_DIR}" rev-parse --short=12 HEAD
    OUTPUT_VARIABLE REVISION OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET RESULT_VARIABLE failed)
  if(failed OR NOT REVISION)
    set(REVISION unknown)
  else()
    execute_process(COMMAND git -C "${SOURCE_DIR}" diff --quiet HEAD -- RESULT_VARIABLE dirty ERROR_QUIET)
    if(dirty EQUAL 1)
      string(APPEND REVISION "-dirty")
    endif()
  endif()
endif()
set(text "// Written by kiosk/status/build_info.cmake at build time; do not edit.
#include \"kiosk/status/build_info.h\"

namespace basalt::kiosk {

BuildInfo buildInfo() { return {\"${VERSION}\", \"${REVISION}\", \"${BUILD}\"}; }

}  // namespace basalt::kiosk
")
set(old "")
if(EXISTS "${OUTPUT}")
  file(READ "${OUTPUT}" old)
endif()
if(NOT old STREQUAL text)
  file(WRITE "${OUTPUT}" "${text}")
endif()
