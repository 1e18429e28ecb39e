# Project-wide warnings as errors; applied per target through plslam_warnings.
add_library(plslam_warnings INTERFACE)
target_compile_options(plslam_warnings INTERFACE -Wall -Wextra -Werror)
