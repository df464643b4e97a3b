#include "detslam/synth/sequence.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <map>

#include "detslam/core/check.h"
#include "detslam/synth/hash_noise.h"
#include "detslam/synth/renderer.h"
#include "detslam/synth/scene_builder.h"

namespace detslam {
namespace {

const SynthOptions& Validated(const SynthOptions& options) {
  RequireSynthPreset(options.preset);
  std::string error;
  if (!options.Check(&error)) throw InputError("invalid synth options: " + error);
  return options;
}

}  // namespace

synth::TextureStyle SynthTextureStyle(const SynthOptions& options) {
  const SynthRealism realism = options.RealismOff("rooms") ? SynthRealism::kEasy : options.realism;
  synth::TextureStyle style;
  // Realistic rooms: walls, floor and ceiling with a quarter of the easy mode's marks. Chosen so
  // that FAST corners per frame fall inside the real TUM frames' range (../shared/data; the
  // realism test checks it), not on any SLAM result.
  if (realism == SynthRealism::kRealistic) {
    style.room_clutter = kRealisticRoomClutter;
    style.windows = true;
  }
  return style;
}

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

namespace {
bool RealisticPeople(const SynthOptions& options) {
  return options.RealisticSensor() && !options.RealismOff("people");
}
}  // namespace

SyntheticSequence::SyntheticSequence(const SynthOptions& options)
    : options_(Validated(options)),
      frames_(SynthFrameCount(options)),
      camera_(SynthCamera()),
      scene_(synth::BuildSceneForPreset(options.preset, options.SceneSeed(),
                                        SynthTextureStyle(options))),
      path_(options.preset, options.seed),
      people_(options.preset, options.seed, RealisticPeople(options)) {
  if (!options_.people_dir.empty()) {
    // Realistic people swing their legs (8 gait sprites per photo).
    looks_ = synth::LoadPhotoPeople(options_.people_dir, RealisticPeople(options) ? 8 : 1);
  } else {
    for (int i = 0; i < std::max(1, people_.count()); ++i) {
      looks_.push_back(synth::MakeProceduralPerson(options_.seed * 131 + static_cast<uint64_t>(i)));
    }
  }
  // Realistic effects switched off for ablations.
  if (options_.RealismOff("shutter")) colour_camera_.readout_s = 0;
  if (options_.RealismOff("blur")) colour_camera_.exposure_s = 0;
  if (options_.RealismOff("colour")) {
    colour_camera_.psf_sigma = colour_camera_.read_sigma = colour_camera_.shot_gain = 0;
    colour_camera_.exposure_drift = 0;
  }
  if (options_.RealismOff("quantisation")) kinect_.disparity_step = 1e-6;
  if (options_.RealismOff("noise")) kinect_.sigma_white = kinect_.sigma_correlated = 0;
  if (options_.RealismOff("distortion")) kinect_.bias_amplitude = 0;
  if (options_.RealismOff("dropouts")) {
    kinect_.border_left = kinect_.border_right = kinect_.border_top = kinect_.border_bottom = 0;
    kinect_.shadows = false;
    kinect_.edge_dropout = kinect_.edge_mixed = 0;
    kinect_.grazing_cos_lo = kinect_.dark_lo = -2;
    kinect_.grazing_cos_hi = kinect_.dark_hi = -1;
    kinect_.hole_fraction = 1e-12;
    kinect_.speckle_dropout = 0;
  }
  // The sequence's camera calibration (settings.yaml) states its rolling shutter.
  if (options_.RealisticSensor()) camera_.rolling_shutter_readout = colour_camera_.readout_s;
  if (options_.preset == "sitting_static" && RealisticPeople(options_)) {
    // A closed-lid laptop on the desk in front of the person on the right (its back to the
    // camera); in the twin it stays where it is.
    moved_instance_ = static_cast<uint16_t>(std::max(1, people_.count()) + 1);
    synth::SceneBuilder b(options_.SceneSeed() ^ 0x1A9709ULL, std::move(scene_));
    using synth::SurfaceKind;
    moved_boxes_ = {b.Box({0.32f, 1.40f, 0.755f}, {0.68f, 1.64f, 0.78f}, SurfaceKind::kMetal,
                          SurfaceKind::kMetal),  // base
                    b.Box({0.32f, 1.64f, 0.78f}, {0.68f, 1.665f, 1.02f}, SurfaceKind::kPoster,
                          SurfaceKind::kPoster)};  // lid
    moved_at_ = b.rng().Uniform(2.5, 5.0);
    scene_ = b.Take();
    // The twin's laptop never moves: no instance there.
    for (int i : moved_boxes_) scene_.boxes[i].instance = options_.people ? moved_instance_ : 0;
  }
}

Eigen::Vector3f SyntheticSequence::MovedObjectOffset(double t) const {
  if (moved_boxes_.empty() || !options_.people) return Eigen::Vector3f::Zero();
  // Pushed 0.45 m to the left over 1.5 s (smooth start and stop), back 5 s later.
  auto ease = [](double x) {
    x = std::clamp(x, 0.0, 1.0);
    return x * x * (3.0 - 2.0 * x);
  };
  const double out = ease((t - moved_at_) / 1.5) - ease((t - moved_at_ - 5.0) / 1.5);
  return Eigen::Vector3f(static_cast<float>(-0.45 * out), 0.f, 0.f);
}

const synth::Scene& SyntheticSequence::SceneAt(double t, synth::Scene* storage) const {
  const Eigen::Vector3f offset = MovedObjectOffset(t);
  if (offset.isZero()) return scene_;
  *storage = scene_;  // textures are shared (cv::Mat headers)
  for (int i : moved_boxes_) {
    storage->boxes[i].lo += offset;
    storage->boxes[i].hi += offset;
  }
  return *storage;
}

Timestamp SyntheticSequence::StampOf(int k) const {
  // Whole microseconds so that the 6-decimal text form is exact.
  const int64_t us = static_cast<int64_t>(std::llround(k * 1e6 / camera_.fps));
  return Timestamp{kEpochNs + us * 1000};
}

Timestamp SyntheticSequence::DepthStampOf(int k) const {
  // The depth image arrives a few milliseconds after the colour image, varying per frame (like the
  // Kinect's unsynchronised streams in TUM RGB-D), inside the 0.02 s association window: 2-9 ms
  // in the easy mode (where depth is still rendered at the colour image's pose), 2-17 ms in the
  // realistic one (rendered at its own time).
  const uint64_t h = synth::Mix64(options_.seed ^ (static_cast<uint64_t>(k) * 0x51ED27ULL));
  const int64_t spread_us = options_.realism == SynthRealism::kRealistic ? 15001 : 7001;
  const int64_t offset_us = 2000 + static_cast<int64_t>(h % spread_us);
  return Timestamp{StampOf(k).ns + offset_us * 1000};
}

synth::IdealFrame SyntheticSequence::RenderRollingShutter(double t) const {
  const int w = camera_.width, h = camera_.height;
  synth::IdealFrame out{cv::Mat(h, w, CV_8UC3), cv::Mat(h, w, CV_32F), cv::Mat(h, w, CV_16U),
                        cv::Mat()};
  const int bands = std::clamp(colour_camera_.shutter_bands, 1, h);
  auto people_at = [&](double time) {
    return options_.people ? people_.At(time) : std::vector<synth::PersonState>{};
  };
  for (int b = 0; b < bands; ++b) {
    const int v0 = b * h / bands, v1 = (b + 1) * h / bands;
    // The middle row is exposed at the frame's stamp (its ground-truth pose).
    const double tb = t + ((v0 + v1) * 0.5 - h * 0.5) / h * colour_camera_.readout_s;
    synth::Scene moved;
    synth::RenderIdealRows(SceneAt(tb, &moved), looks_, people_at(tb), camera_,
                           path_.WorldFromCam(tb), v0, v1, &out);
  }
  // Motion blur: the camera's image motion at the median depth for the static scene, and each
  // person's own image motion (body centre) over the person's pixels.
  const double half = 0.5 * colour_camera_.exposure_s;
  const Rigid3d a = path_.WorldFromCam(t - half), b = path_.WorldFromCam(t + half);
  auto shift_of = [&](const Eigen::Vector3d& pa, const Eigen::Vector3d& pb) {
    const Eigen::Vector3d ca = a.Inverse() * pa, cb = b.Inverse() * pb;
    if (ca.z() < 0.1 || cb.z() < 0.1) return cv::Point2f(0.f, 0.f);
    const Eigen::Vector2d ua = camera_.Project(ca), ub = camera_.Project(cb);
    return cv::Point2f(static_cast<float>(ub.x() - ua.x()), static_cast<float>(ub.y() - ua.y()));
  };
  std::vector<float> z(out.depth.begin<float>(), out.depth.end<float>());
  std::nth_element(z.begin(), z.begin() + z.size() / 2, z.end());
  const double zm = std::max(0.5f, z[z.size() / 2]);
  const Eigen::Vector3d centre = path_.WorldFromCam(t) * Eigen::Vector3d(0, 0, zm);
  const cv::Mat sharp = out.bgr.clone();
  synth::ApplyMotionBlur(&out.bgr, shift_of(centre, centre));
  if (options_.people) {
    const std::vector<synth::PersonState> pa = people_.At(t - half), pb = people_.At(t + half);
    for (size_t i = 0; i < pa.size() && i < pb.size(); ++i) {
      const Eigen::Vector3d up(0, 0, 0.5 * pa[i].height);
      const cv::Point2f shift = shift_of(pa[i].foot + up, pb[i].foot + up);
      cv::Mat mask = out.ids == pa[i].id;
      const int grow = static_cast<int>(std::ceil(std::hypot(shift.x, shift.y) / 2.0f));
      if (grow > 0)
        cv::dilate(mask, mask, cv::getStructuringElement(cv::MORPH_RECT,
                                                         cv::Size(2 * grow + 1, 2 * grow + 1)));
      synth::BlurRegion(sharp, mask, shift, &out.bgr);
    }
  }
  return out;
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
  if (options_.RealisticSensor()) return RenderRealistic(std::move(f));
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
  FillInstances(&f);
  return f;
}

SynthFrame SyntheticSequence::RenderRealistic(SynthFrame f) const {
  const int k = f.index;
  const double t = static_cast<double>(k) / camera_.fps;
  synth::IdealFrame colour = RenderRollingShutter(t);
  f.bgr = colour.bgr;
  f.true_depth = colour.depth;
  f.instance_mask = colour.ids;
  // The depth camera's own exposure, at the depth image's stamp.
  const double td = options_.RealismOff("timing") ? t : SecondsOf(f.depth_stamp);
  synth::Scene moved;
  synth::IdealFrame ideal =
      synth::RenderIdeal(SceneAt(td, &moved), looks_,
                         options_.people ? people_.At(td) : std::vector<synth::PersonState>{},
                         camera_, path_.WorldFromCam(td));
  if (options_.Covered(k)) {
    f.bgr.setTo(cv::Scalar::all(0));
    ideal.depth.setTo(0.0f);
    f.instance_mask.setTo(0);
  } else {
    synth::ApplyColourCamera(&f.bgr, colour_camera_, synth::ExposureGain(colour_camera_, options_.seed, t),
                             options_.seed, k);
  }
  const double scale = DepthScaleOf(k);
  const cv::Mat sensed = scale == 1.0 ? ideal.depth : cv::Mat(ideal.depth * scale);
  // The device's fixed distortion belongs to the scene's recording setup (same in every sequence
  // of a scene seed), the noise to the sequence.
  f.depth16 = synth::MakeKinectDepth16(sensed, ideal.ir, camera_, kinect_, options_.SceneSeed() * 977 + 5,
                                       options_.seed, k);
  FillInstances(&f);
  return f;
}

void SyntheticSequence::FillInstances(SynthFrame* frame) const {
  SynthFrame& f = *frame;
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
  for (auto& [id, in] : found) {
    if (moved_instance_ != 0 && id == moved_instance_) in.label = "laptop";
    f.instances.push_back(in);
  }
}

}  // namespace detslam
