# Every dependency comes from a Debian 12 package (scripts/install-deps.sh).
set(PLSLAM_OPENCV_COMPONENTS core imgproc imgcodecs videoio features2d calib3d line_descriptor ximgproc)
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
# cpp-httplib (libcpp-httplib-dev, in scripts/install-deps.sh) is left to the browser viewer, whose
# own target will find it: the library, the CLI and the tests do not use it.
