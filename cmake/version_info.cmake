# Writes OUT, the C++ source of emaki::version(): PROJECT_VERSION, plus "+g<revision>" (and
# ".dirty" with uncommitted changes to tracked files) when SOURCE_DIR is a git checkout and git
# is found. Run at every build (cmake -P), it rewrites OUT only when the text changes, so a new
# commit relinks what uses the version and nothing else is rebuilt. Without git or a .git it is
# PROJECT_VERSION alone: a build from a source archive does not fail.
set(revision "")
find_program(GIT_EXECUTABLE git)
if(GIT_EXECUTABLE AND EXISTS "${SOURCE_DIR}/.git")
  execute_process(COMMAND "${GIT_EXECUTABLE}" -C "${SOURCE_DIR}" rev-parse --short=12 HEAD
                  OUTPUT_VARIABLE head RESULT_VARIABLE failed
                  OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  if(NOT failed AND head MATCHES "^[0-9a-f]+$")
    set(revision "+g${head}")
    execute_process(COMMAND "${GIT_EXECUTABLE}" -C "${SOURCE_DIR}" status --porcelain
                            --untracked-files=no
                    OUTPUT_VARIABLE changes RESULT_VARIABLE failed ERROR_QUIET)
    if(NOT failed AND NOT changes STREQUAL "")
      string(APPEND revision ".dirty")
    endif()
  endif()
endif()
set(text "// Made by cmake/version_info.cmake at build time; not edited by hand.
#include \"core/version.h\"

namespace emaki {
const char* project_version() { return \"${PROJECT_VERSION}\"; }
const char* version() { return \"${PROJECT_VERSION}${revision}\"; }
}  // namespace emaki
")
set(old "")
if(EXISTS "${OUT}")
  file(READ "${OUT}" old)
endif()
if(NOT old STREQUAL text)
  file(WRITE "${OUT}" "${text}")
endif()
