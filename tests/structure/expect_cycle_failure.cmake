# Structure.CycleCheckFailsOnACycle: cmake/CheckFolderCycles.cmake must fail on cycle_fixture/, a
# made-up src/plslam where alpha and beta include each other (beta through a .cpp), and name the
# cycle and the files behind each arrow. gamma only includes alpha and must not be named (neither
# must the include in a comment of beta.h, which would put it on the cycle); plslam.h sits directly
# in the tree, as the public header will.
#   cmake -DCHECK=<CheckFolderCycles.cmake> -DFIXTURE=<cycle_fixture> -P expect_cycle_failure.cmake
cmake_minimum_required(VERSION 3.25)
execute_process(COMMAND ${CMAKE_COMMAND} -DSRC=${FIXTURE} -P ${CHECK}
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
set(out "${out}${err}")
message("${out}")
if(rc EQUAL 0)
  message(FATAL_ERROR "the check passed on a tree with a cycle")
endif()
foreach(expected "include cycle: alpha -> beta -> alpha" "  alpha -> beta via alpha/alpha.h\n"
                 "  beta -> alpha via beta/beta.cpp\n")
  string(FIND "${out}" "${expected}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "the check's output lacks '${expected}'")
  endif()
endforeach()
if(out MATCHES "gamma ->|-> gamma|gamma/gamma")
  message(FATAL_ERROR "the check names gamma, which is not on the cycle")
endif()
