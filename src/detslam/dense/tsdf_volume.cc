#include "detslam/dense/tsdf_volume.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "detslam/core/check.h"
#include "detslam/core/grid_key.h"

namespace detslam {
namespace {

constexpr float kSdfScale = 32767.f;
constexpr int kAllocationStride = 4;  // pixels between the rays that allocate blocks

int FloorDiv(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

void CheckImage(const cv::Mat& m, int type, const cv::Size& size, const char* what) {
  if (m.type() != type || m.size() != size) {
    throw InputError(std::string("TSDF fusion: the ") + what + " image has the wrong type or size (" +
                     std::to_string(m.cols) + "x" + std::to_string(m.rows) + ", camera " +
                     std::to_string(size.width) + "x" + std::to_string(size.height) + ")");
  }
}

}  // namespace

bool TsdfOptions::Check(std::string* error) const {
  const auto fail = [&](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  if (!(voxel_m >= 0.002 && voxel_m <= 0.5)) return fail("voxel size must lie in [0.002, 0.5] m");
  if (!(truncation_m >= voxel_m)) return fail("truncation must be at least one voxel");
  if (!(min_depth_m >= 0 && max_depth_m > min_depth_m && max_depth_m <= 50))
    return fail("depth range must satisfy 0 <= min < max <= 50 m");
  if (max_weight < 1 || max_weight > 60000) return fail("max weight must lie in [1, 60000]");
  if (min_weight < 1 || min_weight > max_weight) return fail("min weight must lie in [1, max]");
  return true;
}

TsdfVolume::TsdfVolume(const TsdfOptions& options) : options_(options) {
  std::string error;
  DETSLAM_CHECK_MSG(options_.Check(&error), error);
}

const TsdfVolume::Block* TsdfVolume::Find(const Eigen::Vector3i& block) const {
  const auto it = index_.find(GridCellKey(block));
  return it == index_.end() ? nullptr : blocks_[it->second].get();
}

size_t TsdfVolume::FindOrAllocate(const Eigen::Vector3i& block) {
  const auto [it, inserted] = index_.emplace(GridCellKey(block), blocks_.size());
  if (inserted) {
    blocks_.push_back(std::make_unique<Block>());
    blocks_.back()->coords = block;
  }
  return it->second;
}

const TsdfVolume::Voxel* TsdfVolume::VoxelAt(const Eigen::Vector3i& v) const {
  const Eigen::Vector3i b(FloorDiv(v.x(), kBlockSide), FloorDiv(v.y(), kBlockSide),
                          FloorDiv(v.z(), kBlockSide));
  const Block* block = Find(b);
  if (block == nullptr) return nullptr;
  const Eigen::Vector3i l = v - b * kBlockSide;
  return &block->voxels[(l.z() * kBlockSide + l.y()) * kBlockSide + l.x()];
}

size_t TsdfVolume::MemoryBytes() const {
  return blocks_.size() * (sizeof(Block) + sizeof(std::unique_ptr<Block>)) +
         index_.size() * (sizeof(uint64_t) + sizeof(size_t) + 2 * sizeof(void*));
}

void TsdfVolume::Integrate(const PinholeCamera& camera, const Rigid3d& world_from_cam,
                           const cv::Mat& depth_m, const cv::Mat& bgr, const cv::Mat& exclude) {
  const cv::Size size(camera.width, camera.height);
  CheckImage(depth_m, CV_32FC1, size, "depth");
  if (!bgr.empty()) CheckImage(bgr, CV_8UC3, size, "colour");
  if (!exclude.empty()) CheckImage(exclude, CV_8UC1, size, "exclusion mask");
  const float voxel = static_cast<float>(options_.voxel_m);
  const float trunc = static_cast<float>(options_.truncation_m);
  const float block_m = voxel * kBlockSide;
  const float min_d = static_cast<float>(options_.min_depth_m);
  const float max_d = static_cast<float>(options_.max_depth_m);
  const auto usable = [&](int u, int v) {
    const float d = depth_m.at<float>(v, u);
    return d >= min_d && d <= max_d && (exclude.empty() || exclude.at<uint8_t>(v, u) == 0);
  };

  // Blocks within the truncation band of the measured surface (allocated if new).
  const Eigen::Matrix3f world_R_cam = world_from_cam.RotationMatrix().cast<float>();
  const Eigen::Vector3f world_t_cam = world_from_cam.translation().cast<float>();
  const float fx = static_cast<float>(camera.fx), fy = static_cast<float>(camera.fy);
  const float cx = static_cast<float>(camera.cx), cy = static_cast<float>(camera.cy);
  std::vector<size_t> visit;
  std::vector<char> listed(blocks_.size(), 0);
  const auto list_block = [&](const Eigen::Vector3i& b) {
    const size_t i = FindOrAllocate(b);
    if (i == listed.size()) listed.push_back(0);  // allocated now
    if (!listed[i]) {
      listed[i] = 1;
      visit.push_back(i);
    }
  };
  const int samples = static_cast<int>(std::ceil(2.f * trunc / (0.5f * block_m))) + 1;
  for (int v = kAllocationStride / 2; v < size.height; v += kAllocationStride) {
    for (int u = kAllocationStride / 2; u < size.width; u += kAllocationStride) {
      if (!usable(u, v)) continue;
      const float d = depth_m.at<float>(v, u);
      const Eigen::Vector3f ray((u - cx) / fx, (v - cy) / fy, 1.f);
      for (int s = 0; s < samples; ++s) {
        const float z = d - trunc + 2.f * trunc * s / static_cast<float>(samples - 1);
        const Eigen::Vector3f p = world_R_cam * (ray * z) + world_t_cam;
        list_block(GridCellOf(p, block_m));
      }
    }
  }
  // Carving: the other allocated blocks whose centre lies in the view, in front of max depth.
  const Eigen::Matrix3f cam_R_world = world_R_cam.transpose();
  const Eigen::Vector3f cam_t_world = -(cam_R_world * world_t_cam);
  if (options_.carve) {
    for (size_t i = 0; i < blocks_.size(); ++i) {
      if (listed[i]) continue;
      const Eigen::Vector3f centre = (blocks_[i]->coords.cast<float>() + Eigen::Vector3f::Constant(0.5f)) * block_m;
      const Eigen::Vector3f c = cam_R_world * centre + cam_t_world;
      if (c.z() <= 0.f || c.z() > max_d + trunc + block_m) continue;
      const float u = fx * c.x() / c.z() + cx, v = fy * c.y() / c.z() + cy;
      if (u < 0.f || v < 0.f || u >= size.width || v >= size.height) continue;
      listed[i] = 1;
      visit.push_back(i);
    }
  }

  // Projective update of every voxel of the listed blocks.
  const int max_w = options_.max_weight;
  for (const size_t i : visit) {
    Block& block = *blocks_[i];
    const Eigen::Vector3f origin = block.coords.cast<float>() * block_m;
    for (int z = 0; z < kBlockSide; ++z) {
      for (int y = 0; y < kBlockSide; ++y) {
        for (int x = 0; x < kBlockSide; ++x) {
          const Eigen::Vector3f pw =
              origin + Eigen::Vector3f(x + 0.5f, y + 0.5f, z + 0.5f) * voxel;
          const Eigen::Vector3f pc = cam_R_world * pw + cam_t_world;
          if (pc.z() <= 0.f) continue;
          const int u = static_cast<int>(std::lround(fx * pc.x() / pc.z() + cx));
          const int v = static_cast<int>(std::lround(fy * pc.y() / pc.z() + cy));
          if (u < 0 || v < 0 || u >= size.width || v >= size.height || !usable(u, v)) continue;
          const float sdf = depth_m.at<float>(v, u) - pc.z();
          if (sdf < -trunc) continue;  // behind the surface: not seen
          const float tsdf = std::min(1.f, sdf / trunc);
          Voxel& vox = block.voxels[(z * kBlockSide + y) * kBlockSide + x];
          const float w = vox.weight;
          const float fused = (vox.sdf / kSdfScale * w + tsdf) / (w + 1.f);
          vox.sdf = static_cast<int16_t>(std::lround(std::clamp(fused, -1.f, 1.f) * kSdfScale));
          if (sdf < trunc && !bgr.empty()) {
            const cv::Vec3b c = bgr.at<cv::Vec3b>(v, u);
            for (int k = 0; k < 3; ++k) {  // stored r g b; the image is b g r
              vox.rgb[k] = static_cast<uint8_t>(
                  std::lround((vox.rgb[k] * w + c[2 - k]) / (w + 1.f)));
            }
          } else if (sdf < trunc && vox.weight == 0) {
            vox.rgb = {128, 128, 128};
          }
          vox.weight = static_cast<uint16_t>(std::min(max_w, vox.weight + 1));
        }
      }
    }
  }
  ++integrated_;
}

std::vector<DensePoint> TsdfVolume::ExtractSurfacePoints() const {
  std::vector<DensePoint> points;
  const float voxel = static_cast<float>(options_.voxel_m);
  const float jump_limit =
      std::min(1.f, 3.f * voxel / static_cast<float>(options_.truncation_m));
  const int min_w = options_.min_weight;
  const auto observed = [&](const Voxel* v) { return v != nullptr && v->weight >= min_w; };
  for (const auto& block_ptr : blocks_) {
    const Block& block = *block_ptr;
    const Eigen::Vector3i base = block.coords * kBlockSide;
    for (int z = 0; z < kBlockSide; ++z) {
      for (int y = 0; y < kBlockSide; ++y) {
        for (int x = 0; x < kBlockSide; ++x) {
          const Voxel& v0 = block.voxels[(z * kBlockSide + y) * kBlockSide + x];
          if (v0.weight < min_w) continue;
          const Eigen::Vector3i g = base + Eigen::Vector3i(x, y, z);
          const float s0 = v0.sdf / kSdfScale;
          const Voxel* next[3];
          const Voxel* prev[3];
          for (int a = 0; a < 3; ++a) {
            next[a] = VoxelAt(g + Eigen::Vector3i::Unit(a));
            prev[a] = VoxelAt(g - Eigen::Vector3i::Unit(a));
          }
          for (int a = 0; a < 3; ++a) {
            if (!observed(next[a])) continue;
            const float s1 = next[a]->sdf / kSdfScale;
            if ((s0 >= 0.f) == (s1 >= 0.f) || std::abs(s0 - s1) > jump_limit) continue;
            const float t = s0 / (s0 - s1);
            DensePoint p;
            p.position = (g.cast<float>() + Eigen::Vector3f::Constant(0.5f)) * voxel +
                         Eigen::Vector3f::Unit(a) * (t * voxel);
            // Gradient by forward differences, backward where the next voxel is unobserved.
            Eigen::Vector3f grad = Eigen::Vector3f::Zero();
            bool full = true;
            for (int b = 0; b < 3 && full; ++b) {
              if (observed(next[b])) {
                grad[b] = next[b]->sdf / kSdfScale - s0;
              } else if (observed(prev[b])) {
                grad[b] = s0 - prev[b]->sdf / kSdfScale;
              } else {
                full = false;
              }
            }
            if (!full || grad.norm() < 1e-6f) grad = Eigen::Vector3f::Unit(a) * (s1 - s0);
            p.normal = grad.normalized();
            for (int k = 0; k < 3; ++k) {
              p.rgb[k] = static_cast<uint8_t>(
                  std::lround(v0.rgb[k] * (1.f - t) + next[a]->rgb[k] * t));
            }
            points.push_back(p);
          }
        }
      }
    }
  }
  return points;
}

UndistortedImages UndistortForFusion(const PinholeCamera& camera, const cv::Mat& depth_m,
                                     const cv::Mat& bgr, const cv::Mat& exclude) {
  if (!camera.HasDistortion()) return {camera, depth_m, bgr, exclude};
  UndistortedImages out{camera, cv::Mat(), cv::Mat(), cv::Mat()};  // remap cannot work in place
  const cv::Matx33d K(camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1);
  const cv::Vec<double, 5> dist(camera.k1, camera.k2, camera.p1, camera.p2, camera.k3);
  const cv::Size size(camera.width, camera.height);
  cv::Mat map_x, map_y;
  cv::initUndistortRectifyMap(K, dist, cv::Mat(), K, size, CV_32FC1, map_x, map_y);
  cv::remap(depth_m, out.depth_m, map_x, map_y, cv::INTER_NEAREST, cv::BORDER_CONSTANT, 0);
  if (!bgr.empty()) cv::remap(bgr, out.bgr, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  if (!exclude.empty())
    cv::remap(exclude, out.exclude, map_x, map_y, cv::INTER_NEAREST, cv::BORDER_CONSTANT, 0);
  out.camera.k1 = out.camera.k2 = out.camera.p1 = out.camera.p2 = out.camera.k3 = 0;
  return out;
}

}  // namespace detslam
