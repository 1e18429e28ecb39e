# The browser viewer's page (web/) and the parts of three.js it loads (web/node_modules, put there
# by `npm ci` in scripts/install-deps.sh), copied into the build tree: `plslam view` serves that
# copy, and nothing is fetched when a page loads. Without node_modules the build goes on and
# `plslam view` says what is missing.
set(PLSLAM_WEB_SOURCE ${CMAKE_SOURCE_DIR}/web)
file(GLOB PLSLAM_WEB_FILES CONFIGURE_DEPENDS ${PLSLAM_WEB_SOURCE}/*.html ${PLSLAM_WEB_SOURCE}/*.js
     ${PLSLAM_WEB_SOURCE}/*.css)
set(PLSLAM_THREE_FILES build/three.module.js build/three.core.js examples/jsm/controls/OrbitControls.js)
set(_outputs)
set(_commands)
foreach(f ${PLSLAM_WEB_FILES})
  get_filename_component(name ${f} NAME)
  list(APPEND _outputs ${PLSLAM_WEB_BUILD_DIR}/${name})
  list(APPEND _commands COMMAND ${CMAKE_COMMAND} -E copy_if_different ${f} ${PLSLAM_WEB_BUILD_DIR}/${name})
endforeach()
set(_three_sources)
foreach(f ${PLSLAM_THREE_FILES})
  set(src ${PLSLAM_WEB_SOURCE}/node_modules/three/${f})
  if(EXISTS ${src})
    list(APPEND _three_sources ${src})
    list(APPEND _outputs ${PLSLAM_WEB_BUILD_DIR}/vendor/three/${f})
    get_filename_component(dir ${PLSLAM_WEB_BUILD_DIR}/vendor/three/${f} DIRECTORY)
    list(APPEND _commands COMMAND ${CMAKE_COMMAND} -E make_directory ${dir}
                          COMMAND ${CMAKE_COMMAND} -E copy_if_different ${src} ${PLSLAM_WEB_BUILD_DIR}/vendor/three/${f})
  endif()
endforeach()
if(NOT EXISTS ${PLSLAM_WEB_SOURCE}/node_modules/three/build/three.module.js)
  message(WARNING "web/node_modules/three is missing: run scripts/install-deps.sh (npm ci in web/); "
                  "`plslam view` will not have its page")
endif()
add_custom_command(OUTPUT ${_outputs} ${_commands} DEPENDS ${PLSLAM_WEB_FILES} ${_three_sources}
                   COMMENT "Copying the viewer's page into ${PLSLAM_WEB_BUILD_DIR}")
add_custom_target(plslam_web DEPENDS ${_outputs})
