// A truncated signed distance volume on a sparse voxel hash (blocks of 8^3 voxels allocated where
// depth was seen), for the dense static map: keyframes' depth images, with the pixels of dynamic
// objects excluded, are fused into it (projective TSDF with a weighted running average, colour
// alongside), and its zero crossings are read out as a coloured point cloud with normals.
//  - Only blocks near a measured surface are allocated; every allocated block in the view whose
//    voxels lie in front of the measured depth is updated as free space ("carving"), so a surface
//    fused once and later seen through (a missed person) fades instead of staying in the map.
//  - Pixels in `exclude` (e.g. the Det-SLAM masks and depth step) update nothing: what a person
//    hides is neither surface nor free space in that frame.
// Not thread-safe; one volume per map.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <unordered_map>
#include <vector>

#include "detslam/core/camera.h"
#include "detslam/core/rigid3d.h"

namespace detslam {

struct TsdfOptions {
  double voxel_m = 0.01;       // voxel edge length (metres)
  double truncation_m = 0.04;  // signed distances are clamped to +-this (metres)
  double min_depth_m = 0.3;    // depth outside [min, max] is not fused (Kinect-class range)
  double max_depth_m = 4.0;
  int max_weight = 64;   // running average over at most this many observations per voxel
  int min_weight = 2;    // voxels observed fewer times are not read out (single-view noise)
  bool carve = true;     // update free space in front of measured depth (see above)
  bool Check(std::string* error) const;
};

struct DensePoint {
  Eigen::Vector3f position;  // world frame, metres
  Eigen::Vector3f normal;    // unit, pointing to the side the surface was seen from
  std::array<uint8_t, 3> rgb{};
};

class TsdfVolume {
 public:
  static constexpr int kBlockSide = 8;  // voxels per block edge
  static constexpr int kBlockVoxels = kBlockSide * kBlockSide * kBlockSide;

  explicit TsdfVolume(const TsdfOptions& options);  // CHECKs options.Check()

  // Fuses one RGB-D image taken at `world_from_cam` by `camera` (an undistorted pinhole: callers
  // undistort first, see UndistortForFusion). depth_m: CV_32FC1 metres (0 = missing) of the
  // camera's size; bgr: CV_8UC3 of the same size or empty (grey points); exclude: CV_8UC1 of the
  // same size, non-zero = not fused, or empty. Throws InputError on a wrong type or size.
  void Integrate(const PinholeCamera& camera, const Rigid3d& world_from_cam, const cv::Mat& depth_m,
                 const cv::Mat& bgr, const cv::Mat& exclude);

  // The surface: one point per zero crossing between neighbouring voxels (both observed at least
  // min_weight times), linearly interpolated, in a deterministic order.
  std::vector<DensePoint> ExtractSurfacePoints() const;

  size_t num_blocks() const { return blocks_.size(); }
  size_t MemoryBytes() const;  // voxel storage and hash table, approximate
  int integrated_images() const { return integrated_; }
  const TsdfOptions& options() const { return options_; }

 private:
  struct Voxel {
    int16_t sdf = 0;      // signed distance / truncation, scaled to +-32767
    uint16_t weight = 0;  // observations averaged (<= max_weight)
    std::array<uint8_t, 3> rgb{};
    uint8_t unused = 0;
  };
  struct Block {
    Eigen::Vector3i coords;  // block index (voxel index / kBlockSide, rounded down)
    std::array<Voxel, kBlockVoxels> voxels;
  };
  const Block* Find(const Eigen::Vector3i& block) const;
  // The block's position in blocks_, allocated if new.
  size_t FindOrAllocate(const Eigen::Vector3i& block);
  // The voxel at a global voxel index, or null when its block is not allocated.
  const Voxel* VoxelAt(const Eigen::Vector3i& voxel) const;

  TsdfOptions options_;
  std::vector<std::unique_ptr<Block>> blocks_;      // in allocation order
  std::unordered_map<uint64_t, size_t> index_;      // GridCellKey(block) -> position in blocks_
  int integrated_ = 0;
};

// The pinhole camera without distortion and the images undistorted for it (depth by nearest
// neighbour, so that no depth is invented across edges); a no-op for a camera without distortion.
struct UndistortedImages {
  PinholeCamera camera;
  cv::Mat depth_m, bgr, exclude;
};
UndistortedImages UndistortForFusion(const PinholeCamera& camera, const cv::Mat& depth_m,
                                     const cv::Mat& bgr, const cv::Mat& exclude);

}  // namespace detslam
