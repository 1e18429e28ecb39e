# -DPLSLAM_SANITIZE=address|undefined|address,undefined|thread
# A sanitizer build is its own configuration: -O1 keeps the runs fast enough for the whole suite
# while keeping stack traces readable (frame pointers, and -g1: the line tables and function names a
# report's stack needs, inlined frames included, without the types and locals of full -g, which made
# objects 4x larger and the ASan build about 40 % slower); UBSan aborts on the first report instead
# of printing and carrying on, so a report fails its test.
if(PLSLAM_SANITIZE)
  set(_san_flags "-fsanitize=${PLSLAM_SANITIZE}" -fno-omit-frame-pointer)
  if(PLSLAM_SANITIZE MATCHES "undefined")
    list(APPEND _san_flags -fno-sanitize-recover=all)
  endif()
  add_compile_options(${_san_flags} -O1 -g1)
  if(PLSLAM_SANITIZE MATCHES "address")
    # Under ASan (__SANITIZE_ADDRESS__) Eigen stops assuming that malloc is 16-byte aligned and
    # allocates with its own aligned malloc (a 16-byte offset). Ceres, Debian's static library built
    # without ASan, shares Eigen's inline allocation functions with this code, and the linker keeps
    # one copy of each: memory allocated one way was freed the other (CI rehearsal of 2026-12-02:
    # bad-free in Ceres' sparse Cholesky, PoseGraph.* and the loop tests). ASan's malloc is 16-byte
    # aligned on x86-64 (Eigen asserts it on every allocation): the same scheme as Ceres'.
    add_compile_definitions(EIGEN_MALLOC_ALREADY_ALIGNED=1)
  endif()
  add_link_options(${_san_flags})
  # halt_on_error and the third-party suppressions, built into every executable made after this.
  add_library(plslam_sanitizer_defaults OBJECT ${CMAKE_CURRENT_LIST_DIR}/sanitizer_defaults.cpp)
  target_compile_definitions(plslam_sanitizer_defaults PRIVATE
    PLSLAM_TSAN_SUPPRESSIONS="${CMAKE_SOURCE_DIR}/scripts/tsan.supp")
  link_libraries(plslam_sanitizer_defaults)
  message(STATUS "plslam: sanitizers ${PLSLAM_SANITIZE}")
endif()
