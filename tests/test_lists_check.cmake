# Read by ctest after tests/test_groups.cmake has defined the tests of every executable. No two
# tests may share a name (a suite split over two executables would give two "Suite.*"), and each
# test named in tests/test_lists.cmake must exist, or its cost and labels (a CI stage's skip) would
# silently stop applying; the latter is not checked when an executable is not built (the
# ThreadSanitizer stage builds only those with threaded tests).
set(_seen "")
set(_twice "")
foreach(_name IN LISTS _plslam_defined)
  list(FIND _seen "${_name}" _at)
  if(_at EQUAL -1)
    list(APPEND _seen "${_name}")
  else()
    list(APPEND _twice "${_name}")
  endif()
endforeach()
if(_twice)
  message(FATAL_ERROR "tests defined twice (a suite in two test executables?): ${_twice}")
endif()
if(NOT _plslam_not_built)
  function(plslam_test name)
    list(FIND _plslam_solo_found "${name}" _at)
    if(_at EQUAL -1)
      message(FATAL_ERROR "tests/test_lists.cmake names ${name}, which no test executable defines")
    endif()
  endfunction()
  function(plslam_suite suite)
  endfunction()
  include(${CMAKE_CURRENT_LIST_DIR}/test_lists.cmake)
endif()
