#include "detslam/synth/sequence.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <map>

#include "detslam/core/check.h"
#include "detslam/synth/hash_noise.h"
#include "detslam/synth/renderer.h"

namespace detslam {
namespace {

const SynthOptions& Validated(const SynthOptions& options) {
  RequireSynthPreset(options.preset);
  std::string error;
  if (!options.Check(&error)) throw InputError("invalid synth options: " + error);
  return options;
}

}  // namespace

PinholeCamera SynthCamera() {
  PinholeCamera cam;
  cam.width = 640;
  cam.height = 480;
  cam.fx = 535.4;
  cam.fy = 539.2;
  cam.cx = 320.1;
  cam.cy = 247.6;
  cam.fps = 30.0;
  cam.depth_map_factor = 5000.0;
  cam.bf = 0.0747 * 535.4;
  cam.th_depth = 40.0;
  cam.rgb_order = true;
  return cam;
}

cv::Mat SynthFrame::Gray() const {
  cv::Mat gray;
  cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
  return gray;
}

cv::Mat SynthFrame::DepthMetres(double depth_map_factor) const {
  cv::Mat depth_m;
  depth16.convertTo(depth_m, CV_32F, 1.0 / depth_map_factor);
  return depth_m;
}

double SynthFrame::Coverage() const {
  if (instance_mask.empty()) return 0.0;
  return static_cast<double>(cv::countNonZero(instance_mask)) / instance_mask.total();
}

SyntheticSequence::SyntheticSequence(const SynthOptions& options)
    : options_(Validated(options)),
      frames_(SynthFrameCount(options)),
      camera_(SynthCamera()),
      scene_(synth::BuildSceneForPreset(options.preset, options.SceneSeed())),
      path_(options.preset, options.seed),
      people_(options.preset, options.seed) {
  if (!options_.people_dir.empty()) {
    looks_ = synth::LoadPhotoPeople(options_.people_dir);
  } else {
    for (int i = 0; i < std::max(1, people_.count()); ++i) {
      looks_.push_back(synth::MakeProceduralPerson(options_.seed * 131 + static_cast<uint64_t>(i)));
    }
  }
}

Timestamp SyntheticSequence::StampOf(int k) const {
  // Whole microseconds so that the 6-decimal text form is exact.
  const int64_t us = static_cast<int64_t>(std::llround(k * 1e6 / camera_.fps));
  return Timestamp{kEpochNs + us * 1000};
}

Timestamp SyntheticSequence::DepthStampOf(int k) const {
  // The depth image arrives 2-9 ms after the colour image, varying per frame (like the Kinect's
  // unsynchronised streams in TUM RGB-D), always well inside the 0.02 s association window.
  const uint64_t h = synth::Mix64(options_.seed ^ (static_cast<uint64_t>(k) * 0x51ED27ULL));
  const int64_t offset_us = 2000 + static_cast<int64_t>(h % 7001);
  return Timestamp{StampOf(k).ns + offset_us * 1000};
}

Rigid3d SyntheticSequence::WorldFromCam(int k) const {
  return path_.WorldFromCam(static_cast<double>(k) / camera_.fps);
}

double SyntheticSequence::DepthScaleOf(int k) const {
  return SynthDepthScale(options_.depth_scale_bias, k, frames_);
}

SynthFrame SyntheticSequence::Render(int k) const {
  DETSLAM_CHECK_MSG(k >= 0 && k < frames_, "frame " << k << " out of range 0.." << frames_ - 1);
  const double t = static_cast<double>(k) / camera_.fps;
  SynthFrame f;
  f.index = k;
  f.stamp = StampOf(k);
  f.depth_stamp = DepthStampOf(k);
  f.world_from_cam = WorldFromCam(k);
  const std::vector<synth::PersonState> people =
      options_.people ? people_.At(t) : std::vector<synth::PersonState>{};
  synth::IdealFrame ideal = synth::RenderIdeal(scene_, looks_, people, camera_, f.world_from_cam);
  f.bgr = ideal.bgr;
  f.true_depth = ideal.depth;
  f.instance_mask = ideal.ids;
  if (options_.motion_blur) {
    // Image motion during a 1/60 s exposure of the point at the median depth on the optical axis
    // (a global linear blur along the camera's image-plane velocity).
    const double exposure = 1.0 / 60.0;
    const Rigid3d a = path_.WorldFromCam(t - 0.5 * exposure),
                  b = path_.WorldFromCam(t + 0.5 * exposure);
    std::vector<float> z(ideal.depth.begin<float>(), ideal.depth.end<float>());
    std::nth_element(z.begin(), z.begin() + z.size() / 2, z.end());
    const double zm = std::max(0.5f, z[z.size() / 2]);
    const Eigen::Vector3d p_world = a * Eigen::Vector3d(0, 0, zm);
    const Eigen::Vector2d uv_a(camera_.cx, camera_.cy);
    const Eigen::Vector2d uv_b = camera_.Project(b.Inverse() * p_world);
    synth::ApplyMotionBlur(&f.bgr, cv::Point2f(static_cast<float>(uv_b.x() - uv_a.x()),
                                               static_cast<float>(uv_b.y() - uv_a.y())));
  }
  if (options_.Covered(k)) {
    // A covered lens: nothing but black and no depth (the depth camera is covered too).
    f.bgr.setTo(cv::Scalar::all(0));
    ideal.depth.setTo(0.0f);
    f.instance_mask.setTo(0);
  } else if (options_.sensor_noise) {
    synth::AddColourNoise(&f.bgr, sensor_, options_.seed, k);
  }
  // A miscalibrated sensor (--depth-scale-bias): every depth it measures is `scale` x the truth.
  // true_depth and the pose stay true.
  const double scale = DepthScaleOf(k);
  const cv::Mat sensed = scale == 1.0 ? ideal.depth : cv::Mat(ideal.depth * scale);
  f.depth16 = synth::MakeDepth16(sensed, camera_, sensor_, options_.seed, k, options_.sensor_noise);
  // Instances: bounding boxes of the visible mask pixels.
  std::map<int, SynthInstance> found;
  for (int v = 0; v < f.instance_mask.rows; ++v) {
    const uint16_t* row = f.instance_mask.ptr<uint16_t>(v);
    for (int u = 0; u < f.instance_mask.cols; ++u) {
      if (row[u] == 0) continue;
      SynthInstance& in = found[row[u]];
      if (in.pixels == 0) {
        in.id = row[u];
        in.box = cv::Rect(u, v, 1, 1);
      } else {
        in.box |= cv::Rect(u, v, 1, 1);
      }
      ++in.pixels;
    }
  }
  for (auto& [id, in] : found) f.instances.push_back(in);
  return f;
}

}  // namespace detslam
