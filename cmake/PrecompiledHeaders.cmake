# Precompiled headers: the standard and third-party headers nearly every unit of the library, the
# CLI and the tests includes. Each unity batch and each file of the CLI parsed them anew, about 5 s
# of an ASan unit's 15-55 s; now a target parses them once (the tests share one set). Every file
# still includes what it uses: -DPLSLAM_PRECOMPILE_HEADERS=OFF builds the same sources without them.
option(PLSLAM_PRECOMPILE_HEADERS "Precompile the common standard and third-party headers" ON)
set(PLSLAM_PCH_HEADERS
  <algorithm> <array> <cmath> <cstdint> <filesystem> <fstream> <functional> <map> <memory> <mutex>
  <optional> <string> <vector>
  <Eigen/Core> <Eigen/Geometry> <opencv2/core.hpp> <opencv2/imgproc.hpp>
  <fmt/format.h> <spdlog/spdlog.h> <nlohmann/json.hpp>)

# plslam_precompile_headers(<target> [extra headers...])
function(plslam_precompile_headers target)
  if(PLSLAM_PRECOMPILE_HEADERS)
    target_precompile_headers(${target} PRIVATE ${PLSLAM_PCH_HEADERS} ${ARGN})
  endif()
endfunction()

# plslam_reuse_precompiled_headers(<target> <from>): the same set as <from>, which must be compiled
# with the same flags and definitions.
function(plslam_reuse_precompiled_headers target from)
  if(PLSLAM_PRECOMPILE_HEADERS)
    target_precompile_headers(${target} REUSE_FROM ${from})
  endif()
endfunction()
