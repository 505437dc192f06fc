# measured_cost.cmake — a CTest test's COST from tests/suite_seconds.txt (the seconds each test took
# on a clean clone with an empty shader cache): CTest starts a clean build's costliest tests first.
# Included by CMakeLists.txt and by cmake/discover_test_suites.cmake (which runs with -P).

# The lines "NAME SECONDS" of `file` into `out`.
function(obscura_read_test_seconds file out)
  set(lines "")
  if(EXISTS "${file}")
    file(STRINGS "${file}" lines REGEX "^[A-Za-z0-9_./]+ [0-9.]+$")
  endif()
  set(${out} "${lines}" PARENT_SCOPE)
endfunction()

# The seconds `seconds` (obscura_read_test_seconds' list) holds for `test`, else `guess`, into `out`.
function(obscura_measured_cost seconds test guess out)
  set(cost ${guess})
  foreach(entry IN LISTS seconds)
    if(entry MATCHES "^([^ ]+) ([0-9.]+)$" AND CMAKE_MATCH_1 STREQUAL test)
      set(cost ${CMAKE_MATCH_2})
    endif()
  endforeach()
  set(${out} ${cost} PARENT_SCOPE)
endfunction()
