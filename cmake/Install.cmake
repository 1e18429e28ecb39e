# `cmake --install`: the library with its public headers and exported CMake package (plslam::plslam),
# the `plslam` command, the Python module, the configs and the default vocabulary. `cpack` makes a
# Debian package of the same (scripts/package-deb.sh builds it for the /usr prefix).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

install(TARGETS plslam_lib EXPORT plslamTargets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(TARGETS plslam RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY ${CMAKE_SOURCE_DIR}/src/plslam DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
  FILES_MATCHING PATTERN "*.h" PATTERN "*.inc")
install(DIRECTORY ${CMAKE_SOURCE_DIR}/config/ DESTINATION ${CMAKE_INSTALL_DATADIR}/plslam/config)
install(DIRECTORY ${CMAKE_SOURCE_DIR}/data/vocabulary/ DESTINATION ${CMAKE_INSTALL_DATADIR}/plslam/vocabulary)
install(DIRECTORY ${CMAKE_SOURCE_DIR}/data/published/ DESTINATION ${CMAKE_INSTALL_DATADIR}/plslam/published)
# The browser viewer's page with its three.js files, as the build copied them (cmake/WebAssets.cmake).
install(DIRECTORY ${CMAKE_BINARY_DIR}/web/ DESTINATION ${CMAKE_INSTALL_DATADIR}/plslam/web)
install(EXPORT plslamTargets NAMESPACE plslam:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/plslam)

string(REPLACE ";" " " PLSLAM_OPENCV_COMPONENTS "${PLSLAM_OPENCV_COMPONENTS}")
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/plslamConfig.cmake.in
  ${CMAKE_BINARY_DIR}/plslamConfig.cmake
  INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/plslam
  PATH_VARS CMAKE_INSTALL_DATADIR)
# 0.x: a minor version may change the API, so only the same minor version is compatible.
write_basic_package_version_file(${CMAKE_BINARY_DIR}/plslamConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_BINARY_DIR}/plslamConfig.cmake ${CMAKE_BINARY_DIR}/plslamConfigVersion.cmake
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/plslam)

# The Debian package. The program's shared libraries come from dpkg-shlibdeps; the -dev packages a
# program needs to build against the library are recommended, not required.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME plslam)
set(CPACK_PACKAGE_VENDOR "plslam")
set(CPACK_PACKAGE_CONTACT "plslam developers <plslam@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "Stereo point-line visual SLAM: library, command and Python module")
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# The Python module is built for the distribution's python3 (3.11 on Debian 12).
set(CPACK_DEBIAN_PACKAGE_DEPENDS "python3 (>= 3.11), python3 (<< 3.12), python3-numpy")
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS
  "libopencv-dev, libopencv-contrib-dev, libeigen3-dev, libceres-dev, libtbb-dev, libspdlog-dev, libfmt-dev, libyaml-cpp-dev, nlohmann-json3-dev, libdeflate-dev, cmake")
include(CPack)
