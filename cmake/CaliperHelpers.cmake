# One-line helpers so that each unit's CMakeLists.txt says only what it is made of.

# Sanitizers for everything this build directory compiles and links (launch/caliper test --sanitize
# configures build-asan-ubsan/ or build-tsan/ with it): "address,undefined" or "thread". UBSan
# stops at the first report (-fno-sanitize-recover) so that a test fails instead of logging.
set(CALIPER_SANITIZE "" CACHE STRING "Sanitizers: address,undefined or thread (empty: none)")
if(CALIPER_SANITIZE)
  if(CALIPER_SANITIZE MATCHES "thread" AND CALIPER_SANITIZE MATCHES "address")
    message(FATAL_ERROR "CALIPER_SANITIZE: thread cannot be combined with address")
  endif()
  set(_caliper_sanitize_flags -fsanitize=${CALIPER_SANITIZE} -fno-omit-frame-pointer)
  if(CALIPER_SANITIZE MATCHES "undefined")
    list(APPEND _caliper_sanitize_flags -fno-sanitize-recover=undefined)
  endif()
  add_compile_options(${_caliper_sanitize_flags})
  add_link_options(${_caliper_sanitize_flags})
  if(CALIPER_SANITIZE MATCHES "address")
    # Eigen stops trusting malloc's alignment under ASan and frees with its own offset header,
    # while the uninstrumented libpagmo allocates Eigen vectors with plain malloc: a vector made in
    # one and freed in the other is a bad free. glibc's malloc aligns to 16 bytes, Eigen's default.
    add_compile_definitions(EIGEN_MALLOC_ALREADY_ALIGNED=1)
  endif()
  message(STATUS "Caliper: sanitizers ${CALIPER_SANITIZE}")
endif()
# instrumented code runs 2-10 times slower: test timeouts are multiplied by this
if(CALIPER_SANITIZE)
  set(CALIPER_TIMEOUT_FACTOR 3)
else()
  set(CALIPER_TIMEOUT_FACTOR 1)
endif()

# Warnings for Caliper's own code (never for generated code).
function(caliper_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow=local -Wno-missing-field-initializers)
  if(CALIPER_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()

# caliper_hot_path(TARGET): code on the physics step's path (every step of every body, joint,
# tendon and actuator) compiled at -O3 in the default RelWithDebInfo build (-O2 elsewhere): at -O2
# GCC 12 leaves Eigen's small fixed-size products out of line there (a call per point, per joint
# frame). -O3 changes no floating-point semantics (it does not imply -ffast-math). Sanitizer builds
# keep their flags.
function(caliper_hot_path target)
  if(NOT CALIPER_SANITIZE)
    target_compile_options(${target} PRIVATE $<$<CONFIG:RelWithDebInfo>:-O3>)
  endif()
endfunction()

# caliper_library(NAME SOURCES a.cc b.cc DEPS x y [PRIVATE_DEPS z]): libs/<name> -> caliper::<name>
function(caliper_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(caliper_${name} STATIC ${ARG_SOURCES})
  add_library(caliper::${name} ALIAS caliper_${name})
  target_include_directories(caliper_${name} PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include)
  target_link_libraries(caliper_${name} PUBLIC ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  set_target_properties(caliper_${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  caliper_warnings(caliper_${name})
endfunction()

# caliper_executable(NAME SOURCES ... DEPS ...): a program placed in <build>/bin
function(caliper_executable name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS})
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/bin)
  caliper_warnings(${name})
endfunction()

# caliper_test(NAME SOURCES ... DEPS ... [LABELS l] [TIMEOUT s]): a GoogleTest program run by ctest.
# Its main (tests/support/gtest_main.cc) exits 77 when tests were skipped and none failed, and
# ctest reports that as Skipped, not Passed (SKIP_RETURN_CODE). Unlabelled tests are the unit
# tests (one process, no display); LABELS integration / gui mark the others.
function(caliper_test name)
  cmake_parse_arguments(ARG "" "TIMEOUT" "SOURCES;DEPS;LABELS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} caliper_gtest_main GTest::gtest)
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
  caliper_warnings(${name})
  add_test(NAME ${name} COMMAND ${name})
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 120)
  endif()
  math(EXPR ARG_TIMEOUT "${ARG_TIMEOUT} * ${CALIPER_TIMEOUT_FACTOR}")
  set_tests_properties(${name} PROPERTIES TIMEOUT ${ARG_TIMEOUT} SKIP_RETURN_CODE 77
    LABELS "${ARG_LABELS}"
    ENVIRONMENT "CALIPER_BIN_DIR=${CMAKE_BINARY_DIR}/bin;CALIPER_CONFIG_DIR=${CMAKE_SOURCE_DIR}/config;CALIPER_SOURCE_DIR=${CMAKE_SOURCE_DIR};CALIPER_CORPUS_DEFAULT=${CMAKE_SOURCE_DIR}/../shared/corpus")
endfunction()

# caliper_find_mujoco(VAR): finds MuJoCo 2.2.2 (libmujoco-dev, the benchmarks' and cross-checks'
# reference) in the calling directory and sets VAR to TRUE when mujoco::mujoco can be linked.
# Debian's mujoco target names an include directory that does not exist: dropped here.
function(caliper_find_mujoco var)
  find_package(mujoco CONFIG QUIET)
  if(NOT mujoco_FOUND)
    set(${var} FALSE PARENT_SCOPE)
    return()
  endif()
  get_target_property(_mj_inc mujoco::mujoco INTERFACE_INCLUDE_DIRECTORIES)
  list(FILTER _mj_inc EXCLUDE REGEX "qhull")
  set_target_properties(mujoco::mujoco PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_mj_inc}")
  set(${var} TRUE PARENT_SCOPE)
endfunction()
