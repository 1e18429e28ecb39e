// Default runtime options of the sanitizers, compiled into every executable of a sanitizer build
// (cmake/Sanitizers.cmake), so that the tests, the plslam CLI they start, and a hand-run binary all
// stop at the first report. Options in ASAN_OPTIONS / UBSAN_OPTIONS / TSAN_OPTIONS still override.
extern "C" {
// NOLINTBEGIN(readability-identifier-naming): names fixed by the sanitizer runtimes.
const char* __asan_default_options() {
  return "halt_on_error=1:detect_leaks=1:detect_stack_use_after_return=1:strict_string_checks=1";
}
const char* __ubsan_default_options() { return "halt_on_error=1:print_stacktrace=1"; }
const char* __tsan_default_options() {
  return "halt_on_error=1:second_deadlock_stack=1:suppressions=" PLSLAM_TSAN_SUPPRESSIONS;
}
// NOLINTEND(readability-identifier-naming)
}
