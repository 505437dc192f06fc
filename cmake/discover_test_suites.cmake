# discover_test_suites.cmake — run after obscura_tests is linked and when tests/suite_seconds.txt
# changes (cmake -P; CMakeLists.txt's obscura_test_suites target): lists its tests and
# writes one CTest test per GoogleTest suite, run as `obscura_tests --gtest_filter=Suite.*`.
#
# Why per suite and not per test (gtest_discover_tests): on lavapipe most of a small GPU test's
# time is building its pipelines (the validation layer and lavapipe's compiler: ~70 % of a
# 3 s relighting test), plus ~0.45 s of loading the libraries OpenImageIO links. One process per
# suite builds each pipeline once for all its tests (gpu::PipelineCache) and loads once: the
# Relight suite's 16 tests take 10 s in one process against 89 s in sixteen. A failing test is
# still named in the output (--output-on-failure), and every test still fails on a validation
# message of its own (tests/gpu_test.h).
#
# Inputs (-D): TEST_EXECUTABLE, CTEST_FILE (written), TEST_TIMEOUT (seconds per suite),
# SUITE_ENVIRONMENT: "Suite=NAME=VALUE" entries (;-separated) that one suite's process runs with
# besides OBSCURA_VALIDATE=1, and SUITE_SECONDS: tests/suite_seconds.txt (each test's measured seconds).
execute_process(COMMAND "${TEST_EXECUTABLE}" --gtest_list_tests
                OUTPUT_VARIABLE listing RESULT_VARIABLE status ERROR_VARIABLE errors)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "${TEST_EXECUTABLE} --gtest_list_tests failed (${status}): ${errors}")
endif()
string(REPLACE "\n" ";" lines "${listing}")
set(content "# Written by cmake/discover_test_suites.cmake after obscura_tests was linked.\n")
include("${CMAKE_CURRENT_LIST_DIR}/measured_cost.cmake")
obscura_read_test_seconds("${SUITE_SECONDS}" measured)
set(suite "")
set(count 0)
macro(flush_suite)
  if(NOT suite STREQUAL "")
    set(environment "OBSCURA_VALIDATE=1")
    foreach(entry IN LISTS SUITE_ENVIRONMENT)
      if(entry MATCHES "^${suite}=(.+)$")
        string(APPEND environment ";${CMAKE_MATCH_1}")
      endif()
    endforeach()
    # COST: CTest starts the costliest first on a clean build (no timings yet): the seconds the
    # suite took on a clean clone (SUITE_SECONDS), else its number of tests. By the number of tests
    # alone a long suite of one test (RecoverClassroom, 12 s) started last and the suite's 414 s
    # of tests took 249 s on 2 cores.
    obscura_measured_cost("${measured}" ${suite} ${count} cost)
    string(APPEND content
           "add_test([=[${suite}]=] [=[${TEST_EXECUTABLE}]=] [=[--gtest_filter=${suite}.*]=])\n"
           "set_tests_properties([=[${suite}]=] PROPERTIES ENVIRONMENT \"${environment}\" "
           "TIMEOUT ${TEST_TIMEOUT} COST ${cost} LABELS gtest)\n")
  endif()
endmacro()
foreach(line IN LISTS lines)
  if(line MATCHES "^([A-Za-z0-9_/]+)\\.")
    set(next_suite "${CMAKE_MATCH_1}") # before flush_suite(), whose matching sets CMAKE_MATCH_1
    flush_suite()
    set(suite "${next_suite}")
    set(count 0)
  elseif(line MATCHES "^  [A-Za-z0-9_/]+")
    math(EXPR count "${count} + 1")
  endif()
endforeach()
flush_suite()
file(WRITE "${CTEST_FILE}" "${content}")
