# Compiler warnings, sanitizers and the ccache launcher, applied to every Basalt target
# through basalt_target_defaults().

option(BASALT_WERROR "Treat compiler warnings as errors" OFF)
# The sanitizer build runs no benchmark, so it need not build them (CI time).
option(BASALT_BENCH "Build the benchmarks (tests/bench)" ON)
set(BASALT_SANITIZE "" CACHE STRING
    "Sanitizers to build with: a comma-separated subset of address,undefined,thread")
# The fuzz build (scripts/fuzz.sh, clang-19): libFuzzer targets instead of the corpus replay tests,
# and every Basalt library compiled with libFuzzer's coverage instrumentation
# (-fsanitize=fuzzer-no-link), so that the fuzzer's feedback sees the parsers' branches and not
# only those of the target's own file. Third-party libraries are linked as Debian ships them.
option(BASALT_FUZZ "Build libFuzzer targets (clang only) instead of the corpus replay tests" OFF)
# The fuzz coverage build (scripts/fuzz-coverage.sh, clang-19): source-based line coverage
# (-fprofile-instr-generate -fcoverage-mapping) of every Basalt target, read with llvm-cov.
option(BASALT_COVERAGE "Build with clang's source-based coverage (clang only)" OFF)
if((BASALT_FUZZ OR BASALT_COVERAGE) AND NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
  message(FATAL_ERROR "BASALT_FUZZ and BASALT_COVERAGE need clang (scripts/fuzz.sh uses clang-19)")
endif()

find_program(BASALT_CCACHE ccache)
if(BASALT_CCACHE AND NOT CMAKE_CXX_COMPILER_LAUNCHER)
  set(CMAKE_CXX_COMPILER_LAUNCHER ${BASALT_CCACHE})
  set(CMAKE_C_COMPILER_LAUNCHER ${BASALT_CCACHE})
endif()

set(BASALT_WARNINGS -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Wold-style-cast
    -Wcast-align -Wunused -Woverloaded-virtual -Wconversion -Wsign-conversion
    -Wnull-dereference -Wdouble-promotion -Wformat=2 -Wimplicit-fallthrough)
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  list(APPEND BASALT_WARNINGS -Wmisleading-indentation -Wduplicated-cond -Wlogical-op)
endif()
if(BASALT_WERROR)
  list(APPEND BASALT_WARNINGS -Werror)
endif()

if(BASALT_SANITIZE)
  string(REPLACE "," ";" _basalt_san_list "${BASALT_SANITIZE}")
  foreach(_san IN LISTS _basalt_san_list)
    add_compile_options(-fsanitize=${_san})
    add_link_options(-fsanitize=${_san})
  endforeach()
  add_compile_options(-fno-omit-frame-pointer -fno-sanitize-recover=undefined)
endif()

if(BASALT_COVERAGE)
  add_compile_options(-fprofile-instr-generate -fcoverage-mapping)
  add_link_options(-fprofile-instr-generate)
endif()

# Applies Basalt's warnings and include layout to a target of ours (never to third-party code).
function(basalt_target_defaults target)
  target_compile_options(${target} PRIVATE ${BASALT_WARNINGS})
endfunction()

# basalt_library(NAME folder SOURCES ... DEPENDS ...): the CMake library for one top-level folder.
# Public headers are included as "folder/file.h", so the include root is the source tree.
function(basalt_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC;PRIVATE" ${ARGN})
  add_library(basalt_${name} STATIC ${ARG_SOURCES})
  target_include_directories(basalt_${name} PUBLIC ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR}/generated)
  target_link_libraries(basalt_${name} PUBLIC ${ARG_PUBLIC} PRIVATE ${ARG_PRIVATE})
  set_target_properties(basalt_${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  basalt_target_defaults(basalt_${name})
  if(BASALT_FUZZ)
    # Coverage feedback only: the fuzz target's link (-fsanitize=fuzzer) brings libFuzzer itself.
    target_compile_options(basalt_${name} PRIVATE -fsanitize=fuzzer-no-link)
  endif()
endfunction()
