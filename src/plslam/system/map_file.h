#pragma once
// The map file (.plmap): what a later run needs to relocalize in a map, track in it and keep
// mapping it: the calibration, the vocabulary's identity, the configuration that built it, the
// keyframes (pose, keypoints, descriptors, stereo depths, lines, bag of words), the map points and
// lines (position, descriptor, viewing range, observations), the covisibility graph, spanning
// tree and loop edges, and a stereo-inertial map's IMU states. Only active objects are written;
// ids are kept.
//
// Format, little-endian:
//   header   char[8] "plslmap\0", u32 version (2; 1 is read too), u32 section count (6; 5 in version 1)
//   section  char[4] tag, u64 payload bytes, u64 checksum of the payload, payload
//   sections META (calibration, vocabulary identity, next ids, ground-truth anchor, config text), KFRM (keyframes),
//            MPTS (map points), MLIN (map lines), GRPH (covisibility, parent, loop edges), in order;
//            version 2 adds IMUS (whether the world's z axis is up; per keyframe with an IMU state:
//            velocity, biases, the keyframe before it in the IMU chain and the IMU samples between
//            the two with the bias and noise they were integrated with).
// The checksum is FNV-1a 64 taken over 8-byte words (then the tail bytes): a flipped bit anywhere
// changes it, at a byte-wise FNV's strength and 8x its speed.
//
// Written by hand rather than with nlohmann-json's msgpack: about 95 % of the bytes are flat
// arrays (keypoints, descriptors, depths) that are copied here with one bounds check per array;
// a DOM would create a node per keypoint field, and the goal is a load of <= 0.5 ms per keyframe.
// Every count is checked against the bytes left before anything is allocated, and every id and
// index is checked before objects are built, so a corrupt file is an InputError, never a crash.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "plslam/core/types.h"
#include "plslam/geometry/se3.h"
#include "plslam/inertial/preintegration.h"
#include "plslam/map/frame_data.h"
#include "plslam/map/map.h"
#include "plslam/place/keyframe_database.h"

namespace plslam::system {

inline constexpr std::uint32_t kMapFileVersion = 2;

struct MapFileMeta {
  std::uint32_t version = kMapFileVersion;
  StereoCalibration calib;
  // The vocabulary whose words the keyframes' bags of words use; 0 when built without one.
  std::uint64_t vocabulary_checksum = 0;
  std::uint32_t vocabulary_words = 0;
  std::uint32_t vocabulary_nodes = 0;
  map::Map::NextIds next_ids;
  // Where the map's world sits in the ground truth's world (for a rendered sequence, its scene's
  // world), from the ground-truth pose of the first keyframe when the mapping dataset had one: a
  // later run in the same world (another path through a rendered scene) is then scored with no
  // alignment at all.
  std::optional<geometry::SE3> T_gt_map;
  std::string created_by;  // plslam version and the dataset
  std::string config;      // the configuration that built the map (YAML)
  // The world's z axis points up (a stereo-inertial run turned it to gravity): a later run with an
  // IMU can use it as it is. False in version 1 files.
  bool gravity_aligned = false;
};

// A keyframe's IMU state (map::KeyFrameImu) with its predecessor by id.
struct SavedImuState {
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  inertial::ImuBias bias;
  bool estimated = false;
  long previous = -1;  // keyframe id; -1: the chain starts here
  std::shared_ptr<const inertial::Preintegration> from_previous;  // set with `previous`
};

struct SavedKeyframe {
  long id = 0;
  std::shared_ptr<const map::FrameData> data;  // calib from the meta section; grid built on reading
  geometry::SE3 T_cw;
  std::shared_ptr<const place::PlaceDescription> place;  // null when it was not in the database
  long parent = -1;                                      // -1: a spanning-tree root
  std::vector<std::pair<long, int>> covisibility;        // keyframe id, weight; by id
  std::vector<long> loop_edges;
  std::optional<SavedImuState> imu;
};

// A map point (a = position) or a map line (a = start, b = end).
struct SavedLandmark {
  long id = 0;
  long created_frame = 0;
  long reference = -1;  // keyframe id
  Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::Zero();
  double level0_max_distance = 0;  // points only
  map::LandmarkState state;
  std::vector<std::pair<long, int>> observations;  // keyframe id, feature index; by id
};

struct MapContents {
  MapFileMeta meta;
  std::vector<SavedKeyframe> keyframes;  // by id
  std::vector<SavedLandmark> points, lines;
};

// The active part of `map` (call with local mapping and loop closing idle). `database` may be
// null; `meta`'s next ids are taken from the map.
MapContents capture_map(const map::Map& map, const place::KeyframeDatabase* database, MapFileMeta meta);

std::string map_to_bytes(const MapContents& contents);

struct MapReadOptions {
  // Off only in tests and the fuzz target, to reach the checks behind the checksums.
  bool verify_checksums = true;
};
// Parses and checks everything (structure, sizes, ids, indices, finite numbers): InputError(source,
// one line) for any problem.
MapContents map_from_bytes(std::string_view bytes, const std::string& source, const MapReadOptions& options = {});

// Builds the saved objects into an empty map, and indexes the keyframes that had a description
// in `database` (may be null). Contents from map_from_bytes never fail here. The keyframes share
// their FrameData with `contents` (immutable), so nothing is copied.
void restore_map(const MapContents& contents, map::Map& map, place::KeyframeDatabase* database);

// A map is used only with the calibration it was built with (resolution, intrinsics and baseline
// to 1e-4 relative) and with its vocabulary (a map without one can be used with any: its keyframes
// are described on loading). InputError(source, what differs); `vocabulary` null: none in this run.
void check_map_matches(const MapFileMeta& meta, const StereoCalibration& calib, const place::Vocabulary* vocabulary,
                       const std::string& source);

// Atomic (a temporary name, then a rename): InputError naming the path when it cannot be written.
void save_map_file(const std::filesystem::path& path, const MapContents& contents);
// Reads through a private memory mapping of the file (no copy of its bytes).
MapContents load_map_file(const std::filesystem::path& path);

}  // namespace plslam::system
