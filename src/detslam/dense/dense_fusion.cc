#include "detslam/dense/dense_fusion.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <unordered_map>

#include "detslam/core/atomic_file.h"
#include "detslam/core/check.h"
#include "detslam/io/ply.h"

namespace detslam {
namespace {

double SecondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Frame index of a mask file name NNNNNN.png, or -1.
int64_t MaskFrameOf(const std::filesystem::path& p) {
  if (p.extension() != ".png") return -1;
  const std::string stem = p.stem().string();
  if (stem.empty() || stem.size() > 12) return -1;
  for (const char c : stem) {
    if (c < '0' || c > '9') return -1;
  }
  return std::stoll(stem);
}

}  // namespace

TsdfVolume FuseKeyframes(const RgbdSource& source, const PinholeCamera& camera,
                         const std::vector<DenseKeyframe>& keyframes, const TsdfOptions& options,
                         DenseMapStats* stats, const DenseProgressFn& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  TsdfVolume volume(options);
  DenseMapStats local;
  DenseMapStats& s = stats ? *stats : local;
  for (size_t i = 0; i < keyframes.size(); ++i) {
    const DenseKeyframe& kf = keyframes[i];
    RgbdImages images;
    try {
      images = source.Load(kf.frame, camera);
    } catch (const InputError& e) {
      spdlog::warn("dense map: keyframe of frame {} skipped: {}", kf.frame, e.what());
      ++s.unreadable;
      continue;
    }
    cv::Mat exclude;
    if (!kf.exclude_png.empty()) {
      exclude = DecodeKeyframeMask(kf.exclude_png);
      if (exclude.empty() || exclude.size() != images.depth_m.size()) {
        throw InputError("dense map: the mask of frame " + std::to_string(kf.frame) +
                         " is not an 8-bit mask of the image's size");
      }
    }
    const UndistortedImages u = UndistortForFusion(camera, images.depth_m, images.bgr, exclude);
    volume.Integrate(u.camera, kf.world_from_cam, u.depth_m, u.bgr, u.exclude);
    ++s.keyframes;
    if (progress) progress(i + 1, keyframes.size());
  }
  s.blocks = volume.num_blocks();
  s.memory_mb = volume.MemoryBytes() / 1e6;
  s.fusion_s = SecondsSince(t0);
  return volume;
}

void WriteDenseMap(const TsdfVolume& volume, const std::string& path, DenseMapStats* stats) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<DensePoint> surface = volume.ExtractSurfacePoints();
  std::vector<Eigen::Vector3d> points, normals;
  std::vector<Eigen::Matrix<uint8_t, 3, 1>> colors;
  points.reserve(surface.size());
  normals.reserve(surface.size());
  colors.reserve(surface.size());
  for (const DensePoint& p : surface) {
    points.push_back(p.position.cast<double>());
    normals.push_back(p.normal.cast<double>());
    colors.emplace_back(p.rgb[0], p.rgb[1], p.rgb[2]);
  }
  WritePointCloudPly(path, points, colors, normals);
  if (stats) {
    stats->points = surface.size();
    stats->extraction_s = SecondsSince(t0);
  }
}

std::string EncodeKeyframeMask(const cv::Mat& mask) {
  DETSLAM_CHECK(mask.type() == CV_8UC1);
  std::vector<uint8_t> png;
  DETSLAM_CHECK(cv::imencode(".png", mask, png));
  return std::string(png.begin(), png.end());
}

cv::Mat DecodeKeyframeMask(const std::string& png) {
  if (png.empty()) return cv::Mat();
  const cv::Mat m = cv::imdecode(
      cv::Mat(1, static_cast<int>(png.size()), CV_8UC1, const_cast<char*>(png.data())),
      cv::IMREAD_UNCHANGED);
  return m.type() == CV_8UC1 ? m : cv::Mat();
}

std::vector<DenseKeyframe> MatchKeyframes(const RgbdSource& source, const Trajectory& keyframe_poses,
                                          const KeyframeMasks& masks, size_t* unmatched) {
  std::unordered_map<int64_t, size_t> by_us;  // stamp in whole microseconds -> frame
  for (size_t i = 0; i < source.size(); ++i) {
    by_us.emplace(static_cast<int64_t>(std::llround(source.stamp(i).ns / 1e3)), i);
  }
  std::vector<DenseKeyframe> out;
  size_t missing = 0;
  for (const StampedPose& p : keyframe_poses) {
    const auto it = by_us.find(static_cast<int64_t>(std::llround(p.stamp.ns / 1e3)));
    if (it == by_us.end()) {
      ++missing;
      continue;
    }
    DenseKeyframe kf;
    kf.frame = it->second;
    kf.world_from_cam = p.world_from_cam;
    const auto m = masks.find(kf.frame);
    if (m != masks.end()) kf.exclude_png = m->second;
    out.push_back(std::move(kf));
  }
  if (unmatched) *unmatched = missing;
  return out;
}

std::string KeyframeMaskPath(const std::string& dir, size_t frame) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06zu.png", frame);
  return (std::filesystem::path(dir) / name).string();
}

void WriteKeyframeMasks(const std::string& dir, const KeyframeMasks& masks) {
  namespace fs = std::filesystem;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (MaskFrameOf(entry.path()) >= 0) fs::remove(entry.path(), ec);
  }
  if (masks.empty()) return;
  fs::create_directories(dir, ec);
  if (ec) throw InputError(dir, 0, "cannot create the keyframe mask folder: " + ec.message());
  for (const auto& [frame, png] : masks) WriteBytesAtomically(KeyframeMaskPath(dir, frame), png);
}

KeyframeMasks ReadKeyframeMasks(const std::string& dir) {
  namespace fs = std::filesystem;
  KeyframeMasks masks;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return masks;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const int64_t frame = MaskFrameOf(entry.path());
    if (frame < 0) continue;
    std::ifstream in(entry.path(), std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (DecodeKeyframeMask(bytes).empty()) {
      throw InputError(entry.path().string(), 0,
                       "not a keyframe mask (an 8-bit single-channel PNG)");
    }
    masks[static_cast<size_t>(frame)] = std::move(bytes);
  }
  return masks;
}

}  // namespace detslam
