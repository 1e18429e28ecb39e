# Every dependency comes from a Debian 12 package (scripts/install-deps.sh).
set(PLSLAM_OPENCV_COMPONENTS core imgproc imgcodecs videoio features2d calib3d line_descriptor ximgproc aruco)
find_package(OpenCV 4.6 REQUIRED COMPONENTS ${PLSLAM_OPENCV_COMPONENTS})
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(Ceres 2.1 REQUIRED)
find_package(TBB REQUIRED)
find_package(CLI11 CONFIG REQUIRED)
find_package(fmt REQUIRED)
find_package(spdlog REQUIRED)
find_package(yaml-cpp REQUIRED)
find_package(nlohmann_json 3 REQUIRED)
find_package(Threads REQUIRED)
# libdeflate (libdeflate-dev): io/png_grey's fast path for the datasets' greyscale PNGs. Linked
# by name, so the exported static library asks its users' linker for -ldeflate.
find_library(PLSLAM_LIBDEFLATE NAMES deflate REQUIRED)
find_path(PLSLAM_LIBDEFLATE_INCLUDE_DIR libdeflate.h REQUIRED)
# cpp-httplib (libcpp-httplib-dev): Debian builds it as a shared library whose header must be
# compiled with the same feature macros, which its pkg-config file gives. Only the viewer
# (plslam_viz) links it.
find_package(PkgConfig REQUIRED)
pkg_check_modules(CPP_HTTPLIB REQUIRED IMPORTED_TARGET cpp-httplib)
