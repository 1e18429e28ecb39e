# Defines the tests of one GoogleTest executable for ctest, at ctest time (TEST_INCLUDE_FILES, set
# up by tests/CMakeLists.txt with _plslam_exe, _plslam_dir and _plslam_cache). The tests named in
# tests/test_lists.cmake (plslam_test) run one by one, under their own names, with their COST and
# LABELS (and their suite's labels); the other tests of each suite run as one test, "Suite.*", in one
# process, with the suite's COST and LABELS where it is listed (plslam_suite).
#
# Why: each process of a test executable loads ~270 shared libraries (OpenCV's image codecs and
# video I/O bring GDAL, GDCM, FFmpeg, ...). An executable that runs no test takes 0.23 s in
# Release, 0.60 s under AddressSanitizer (with its leak check at exit) and 0.53 s under
# ThreadSanitizer (medians of 5 and 3 runs), more than most tests take: with one process for each
# of ~630 tests, that was about 4 of CI's 60 minutes.
#
# The list of tests is cached in _plslam_cache and read again only when the executable or the lists
# are newer (as gtest_discover_tests does).
set(_plslam_lists ${CMAKE_CURRENT_LIST_DIR}/test_lists.cmake)
if(NOT EXISTS "${_plslam_exe}")
  get_filename_component(_plslam_name "${_plslam_exe}" NAME)
  add_test(${_plslam_name}_NOT_BUILT ${_plslam_name}_NOT_BUILT)
  set(_plslam_not_built TRUE)
  return()
endif()

if(NOT EXISTS "${_plslam_cache}" OR "${_plslam_exe}" IS_NEWER_THAN "${_plslam_cache}" OR
   "${_plslam_lists}" IS_NEWER_THAN "${_plslam_cache}" OR "${CMAKE_CURRENT_LIST_FILE}" IS_NEWER_THAN "${_plslam_cache}")
  # The lists: a test's (or its suite's) cost and labels; a listed test runs by itself.
  function(plslam_test name)
    cmake_parse_arguments(PARSE_ARGV 1 a "" "COST" "LABELS")
    set(_solo_${name} TRUE PARENT_SCOPE)
    set(_cost_${name} "${a_COST}" PARENT_SCOPE)
    set(_labels_${name} "${a_LABELS}" PARENT_SCOPE)
  endfunction()
  function(plslam_suite suite)
    cmake_parse_arguments(PARSE_ARGV 1 a "" "COST" "LABELS")
    set(_suite_listed_${suite} TRUE PARENT_SCOPE)
    set(_suite_cost_${suite} "${a_COST}" PARENT_SCOPE)
    set(_suite_labels_${suite} "${a_LABELS}" PARENT_SCOPE)
  endfunction()
  include(${_plslam_lists})

  execute_process(COMMAND "${_plslam_exe}" --gtest_list_tests WORKING_DIRECTORY "${_plslam_dir}" TIMEOUT 60
                  OUTPUT_VARIABLE _out RESULT_VARIABLE _rc)
  if(NOT _rc EQUAL 0)
    message(FATAL_ERROR "${_plslam_exe} --gtest_list_tests failed (${_rc}):\n${_out}")
  endif()
  string(REPLACE ";" "\\;" _out "${_out}")
  string(REPLACE "\n" ";" _out "${_out}")
  set(_script "")
  set(_suites "")
  set(_suite "")
  foreach(_line IN LISTS _out)
    if(_line MATCHES "^[^ ]")  # "Suite." or "Prefix/Suite.  # TypeParam = ..."
      string(REGEX REPLACE "\\.( +#.*)?$" "" _suite "${_line}")
      list(APPEND _suites "${_suite}")
      set(_members_${_suite} "")
    elseif(_line MATCHES "^  ")  # "  Test" or "  Test/0  # GetParam() = ..."
      string(REGEX REPLACE "^ +([^ ]+).*$" "\\1" _test "${_line}")
      set(_name "${_suite}.${_test}")
      if(_solo_${_name})
        set(_props "TIMEOUT 900 SKIP_REGULAR_EXPRESSION \"\\\\[  SKIPPED \\\\]\"")
        set(_labels ${_labels_${_name}} ${_suite_labels_${_suite}})
        if(_labels)
          list(REMOVE_DUPLICATES _labels)
          string(APPEND _props " LABELS \"${_labels}\"")
        endif()
        if(_cost_${_name})
          string(APPEND _props " COST ${_cost_${_name}}")
        endif()
        string(APPEND _script "add_test([==[${_name}]==] \"${_plslam_exe}\" [==[--gtest_filter=${_name}]==])\n"
                              "set_tests_properties([==[${_name}]==] PROPERTIES WORKING_DIRECTORY \"${_plslam_dir}\" ${_props})\n"
                              "list(APPEND _plslam_solo_found [==[${_name}]==])\n"
                              "list(APPEND _plslam_defined [==[${_name}]==])\n")
      else()
        list(APPEND _members_${_suite} "${_name}")
      endif()
    endif()
  endforeach()
  foreach(_suite IN LISTS _suites)
    if(NOT _members_${_suite})
      continue()
    endif()
    list(JOIN _members_${_suite} ":" _filter)
    # A suite's tests pass or fail together; the output names the failing ones. A suite in the lists
    # (plslam_suite) has its cost and labels.
    set(_props "TIMEOUT 900")
    if(_suite_labels_${_suite})
      string(APPEND _props " LABELS \"${_suite_labels_${_suite}}\"")
    endif()
    if(_suite_cost_${_suite})
      string(APPEND _props " COST ${_suite_cost_${_suite}}")
    endif()
    string(APPEND _script "add_test([==[${_suite}.*]==] \"${_plslam_exe}\" [==[--gtest_filter=${_filter}]==])\n"
                          "set_tests_properties([==[${_suite}.*]==] PROPERTIES WORKING_DIRECTORY \"${_plslam_dir}\" ${_props})\n"
                          "list(APPEND _plslam_defined [==[${_suite}.*]==])\n")
    if(_suite_listed_${_suite})
      string(APPEND _script "list(APPEND _plslam_suites_found [==[${_suite}]==])\n")
    endif()
  endforeach()
  file(WRITE "${_plslam_cache}" "${_script}")
endif()
include("${_plslam_cache}")
