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
  add_link_options(${_san_flags})
  # halt_on_error and the third-party suppressions, built into every executable made after this.
  add_library(plslam_sanitizer_defaults OBJECT ${CMAKE_CURRENT_LIST_DIR}/sanitizer_defaults.cpp)
  target_compile_definitions(plslam_sanitizer_defaults PRIVATE
    PLSLAM_TSAN_SUPPRESSIONS="${CMAKE_SOURCE_DIR}/scripts/tsan.supp")
  link_libraries(plslam_sanitizer_defaults)
  message(STATUS "plslam: sanitizers ${PLSLAM_SANITIZE}")
endif()
