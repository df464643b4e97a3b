// Map files: the whole atlas (every map: keyframes with keypoints, descriptors and bag-of-words data, map points,
// covisibility and spanning tree) with the camera, the scale pyramid and the vocabulary it was
// made with, in a versioned little-endian binary format closed by a checksum (format in
// map_file.cc). Written atomically; a file that is truncated, corrupt, of another version, or made
// with another camera, pyramid or vocabulary is refused with an InputError that names the file and
// the problem.
#pragma once

#include <cstdint>
#include <string>

#include "detslam/core/camera.h"
#include "detslam/map/map.h"

namespace detslam {

constexpr uint32_t kMapFileVersion = 2;

// What a map file holds besides the map (its header).
struct MapFileInfo {
  uint32_t version = 0;
  PinholeCamera camera;  // intrinsics, distortion, image size and bf as written
  double scale_factor = 0;
  int levels = 0;
  uint64_t vocabulary_checksum = 0;  // Vocabulary::Checksum(); 0: made without a vocabulary
  uint64_t keyframes = 0, landmarks = 0;
  uint64_t bytes = 0;
};

// What the map must have been made with to be used by this run.
struct MapFileExpectation {
  PinholeCamera camera;
  ScaleInfo scale;
  uint64_t vocabulary_checksum = 0;
};

// The file's bytes (deterministic: the same map gives the same bytes).
std::string EncodeMapFile(const Map& map, const PinholeCamera& camera,
                          uint64_t vocabulary_checksum);
// Writes EncodeMapFile atomically; throws InputError naming `path` on failure.
void SaveMapFile(const std::string& path, const Map& map, const PinholeCamera& camera,
                 uint64_t vocabulary_checksum);

// Reads the header (after checking the whole file's checksum).
MapFileInfo ReadMapFileInfo(const std::string& path);
// Reads the map; its keyframes get their keypoint grids from `expected.camera`. Throws InputError
// on any damage or mismatch with `expected` (never a crash).
Map LoadMapFile(const std::string& path, const MapFileExpectation& expected,
                MapFileInfo* info = nullptr);

}  // namespace detslam
