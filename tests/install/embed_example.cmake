# ctest Install.*: installs the build into a temporary prefix, builds examples/embed out of tree
# against it with find_package(plslam), renders a short synthetic sequence with the installed
# `plslam`, tracks it with the example and checks the poses (every frame tracked, ATE bound). The
# installed Python module is imported from the prefix as well.
#   cmake -DBUILD_DIR=... -DSOURCE_DIR=... -DWORK_DIR=... [-DPYTHON=...] -P embed_example.cmake
foreach(v BUILD_DIR SOURCE_DIR WORK_DIR)
  if(NOT ${v})
    message(FATAL_ERROR "embed_example.cmake: -D${v}= is required")
  endif()
endforeach()

function(run)
  execute_process(COMMAND ${ARGV} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGV}\n${out}\n${err}")
  endif()
  set(run_output "${out}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})

# What a user finds in the prefix.
foreach(f bin/plslam include/plslam/plslam.h include/plslam/system/slam_system.h lib/libplslam.a
          lib/cmake/plslam/plslamConfig.cmake lib/cmake/plslam/plslamConfigVersion.cmake
          lib/cmake/plslam/plslamTargets.cmake share/plslam/config/euroc.yaml
          share/plslam/vocabulary/plslam_orb_k10_l4.plvoc)
  if(NOT EXISTS ${prefix}/${f})
    message(FATAL_ERROR "the install has no ${f}")
  endif()
endforeach()
run(${prefix}/bin/plslam --version)
message(STATUS "installed: ${run_output}")

# The example, out of tree, finding only the installed package.
run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/examples/embed -B ${WORK_DIR}/embed-build -DCMAKE_BUILD_TYPE=Release
    -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_FIND_PACKAGE_NO_PACKAGE_REGISTRY=ON)
run(${CMAKE_COMMAND} --build ${WORK_DIR}/embed-build -j2)

# 160 frames of the rendered office (EuRoC layout, exact ground truth), from the installed CLI.
run(${prefix}/bin/plslam synth --out ${WORK_DIR}/office --scene office --preset euroc --frames 160 --seed 1)
# The installed vocabulary, not the source tree's: PLSLAM_DATA_DIR points at the prefix.
run(${CMAKE_COMMAND} -E env PLSLAM_DATA_DIR=${prefix}/share/plslam
    ${WORK_DIR}/embed-build/embed ${WORK_DIR}/office ${WORK_DIR}/embed.tum)
message(STATUS "embed: ${run_output}")
# Its stdout is its own: the summary line only (the library logs to stderr).
if(NOT run_output MATCHES "^frames ([0-9]+) tracked ([0-9]+) [^\n]* ate_rmse_m ([0-9.]+)\n$")
  message(FATAL_ERROR "embed printed more or less than its summary on stdout: ${run_output}")
endif()
set(frames ${CMAKE_MATCH_1})
set(tracked ${CMAKE_MATCH_2})
set(ate ${CMAKE_MATCH_3})
if(NOT frames EQUAL 160 OR NOT tracked EQUAL 160)
  message(FATAL_ERROR "embed tracked ${tracked} of ${frames} frames, expected 160 of 160")
endif()
# The full office loop's ATE is under 1 cm (README); a short stretch of it stays well inside 3 cm.
if(ate GREATER 0.03)
  message(FATAL_ERROR "embed's ATE ${ate} m is above 0.03 m")
endif()
file(STRINGS ${WORK_DIR}/embed.tum rows)
list(LENGTH rows n)
if(NOT n EQUAL 160)
  message(FATAL_ERROR "embed.tum has ${n} poses, expected 160")
endif()

if(PYTHON)
  # No semicolons in the script: CMake would split the argument at them.
  run(${CMAKE_COMMAND} -E env PYTHONPATH=${prefix}/lib/python3/dist-packages
      ${PYTHON} -c "import plslam\nprint(plslam.__file__)\nprint(plslam.version())")
  message(STATUS "python from the prefix: ${run_output}")
  if(NOT run_output MATCHES "^${prefix}/lib/python3/dist-packages/plslam[^\n]*[.]so\n0[.]1[.]0")
    message(FATAL_ERROR "python imported plslam from elsewhere than the prefix: ${run_output}")
  endif()
endif()
