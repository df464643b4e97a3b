// The dense static map of a run: the keyframes' depth and colour, re-read from the run's RGB-D
// source, with the pixels the Det-SLAM stage removed (instance masks and the depth step) left
// out, fused at their final poses (after every loop correction and merge) into a TSDF volume, and
// its surface written as a coloured PLY point cloud with normals. Fusing once at the end, from the
// final poses, is how loop and map corrections reach the dense geometry.
// Also the keyframe masks a run writes (RUN_DIR/keyframe_masks/NNNNNN.png, 255 = removed) so that
// `detslam densify` can redo the fusion later with other settings.
#pragma once

#include <functional>
#include <map>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "detslam/dense/tsdf_volume.h"
#include "detslam/io/rgbd_source.h"
#include "detslam/io/trajectory.h"

namespace detslam {

// Keyframe masks by source frame index: PNG-encoded CV_8UC1 images, 255 = removed by the Det-SLAM
// stage (kept encoded: a few kilobytes each instead of a full image per keyframe).
using KeyframeMasks = std::map<size_t, std::string>;

// A mask as the PNG bytes KeyframeMasks holds (CHECKs a CV_8UC1 mask), and back: an empty Mat
// when the bytes are no 8-bit single-channel image (callers name the source in their error).
std::string EncodeKeyframeMask(const cv::Mat& mask);
cv::Mat DecodeKeyframeMask(const std::string& png);

struct DenseKeyframe {
  size_t frame = 0;         // index in the RGB-D source
  Rigid3d world_from_cam;   // final pose
  std::string exclude_png;  // its mask (KeyframeMasks); empty = keep every pixel
};

struct DenseMapStats {
  size_t keyframes = 0;  // fused
  size_t not_in_source = 0;  // keyframes of the map that are no frame of the source (left out)
  size_t unreadable = 0; // keyframes whose images could not be read (skipped with a warning)
  size_t points = 0;     // written
  size_t blocks = 0;     // allocated voxel blocks
  double memory_mb = 0;  // of the volume
  double fusion_s = 0, extraction_s = 0;
};

using DenseProgressFn = std::function<void(size_t done, size_t total)>;

// Fuses `keyframes` (in order) from `source` read with `camera`. A keyframe whose images cannot
// be read is skipped with a warning (counted in the stats).
TsdfVolume FuseKeyframes(const RgbdSource& source, const PinholeCamera& camera,
                         const std::vector<DenseKeyframe>& keyframes, const TsdfOptions& options,
                         DenseMapStats* stats, const DenseProgressFn& progress = nullptr);

// Extracts the surface of `volume` and writes it to `path` (PLY, atomically); fills stats->points.
void WriteDenseMap(const TsdfVolume& volume, const std::string& path, DenseMapStats* stats);

// The keyframes of `keyframe_poses` (stamps of the source's frames, e.g. keyframes.txt) with
// their source frame index and, from `masks` (may be empty), their masks. A keyframe whose stamp
// is no frame of the source (to the microsecond; e.g. one of a map loaded from another session)
// is left out and counted in *unmatched.
std::vector<DenseKeyframe> MatchKeyframes(const RgbdSource& source, const Trajectory& keyframe_poses,
                                          const KeyframeMasks& masks, size_t* unmatched);

// Keyframe masks on disk: `dir`/NNNNNN.png (frame index, zero-padded to 6 digits).
std::string KeyframeMaskPath(const std::string& dir, size_t frame);
// Writes them (atomically, each file) after removing the masks of an earlier run from `dir`.
void WriteKeyframeMasks(const std::string& dir, const KeyframeMasks& masks);
// Reads every NNNNNN.png in `dir` (none if the folder does not exist). Throws InputError naming a
// file that is not an 8-bit single-channel PNG.
KeyframeMasks ReadKeyframeMasks(const std::string& dir);

}  // namespace detslam
