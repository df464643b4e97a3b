// A synthetic dynamic RGB-D sequence rendered frame by frame on demand (no disk needed):
// an office room, a preset camera path, people walking through the view, Kinect-like sensor
// effects, ground-truth poses and per-frame instance masks of the moving people.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "detslam/core/camera.h"
#include "detslam/core/rigid3d.h"
#include "detslam/core/timestamp.h"
#include "detslam/synth/camera_path.h"
#include "detslam/synth/options.h"
#include "detslam/synth/people.h"
#include "detslam/synth/realistic_sensor.h"
#include "detslam/synth/renderer.h"
#include "detslam/synth/scene.h"
#include "detslam/synth/sensor.h"
#include "detslam/synth/texture.h"

namespace detslam {

// How busy the room's surfaces are in a realism mode.
constexpr double kRealisticRoomClutter = 0.25;
synth::TextureStyle SynthTextureStyle(const SynthOptions& options);

// The TUM fr3 (Kinect, Freiburg 3) camera: 640x480, fx 535.4, fy 539.2, cx 320.1, cy 247.6, no
// distortion, depth 5000 per metre, 30 Hz, bf 40 (baseline 0.0747 m).
PinholeCamera SynthCamera();

// One moving object visible in a frame.
struct SynthInstance {
  int id = 0;                    // instance id in the mask (1..N)
  std::string label = "person";  // COCO class name
  float score = 1.0f;            // ground truth: always 1
  cv::Rect box;                  // bounding box of the visible mask pixels
  int pixels = 0;                // number of visible mask pixels
};

struct SynthFrame {
  int index = 0;           // frame number k
  Timestamp stamp;         // colour image time: epoch + k / 30 s (whole microseconds)
  Timestamp depth_stamp;   // depth image time: stamp + a few milliseconds
  Rigid3d world_from_cam;  // ground-truth camera pose at `stamp`
  cv::Mat bgr;             // CV_8UC3 colour (BGR order in memory)
  cv::Mat depth16;         // CV_16U depth, metres * 5000, 0 = missing
  cv::Mat instance_mask;   // CV_16U, 0 static, k = person k
  cv::Mat true_depth;      // CV_32F noise-free depth (metres), for tests and statistics
  std::vector<SynthInstance> instances;  // visible people, by id
  // Fraction of pixels covered by moving objects.
  double Coverage() const;
  // What the SLAM core reads from a dataset: 8-bit grey and depth in metres (CV_32F, 0 = missing),
  // given the camera's depth_map_factor.
  cv::Mat Gray() const;
  cv::Mat DepthMetres(double depth_map_factor) const;
};

class SyntheticSequence {
 public:
  // Builds the scene textures and loads the people. Throws InputError on invalid options, an
  // unknown preset, a missing people folder or a bad cut-out.
  explicit SyntheticSequence(const SynthOptions& options);

  int size() const { return frames_; }
  const SynthOptions& options() const { return options_; }
  const PinholeCamera& camera() const { return camera_; }
  const synth::Scene& scene() const { return scene_; }  // the static world (its boxes)

  Timestamp StampOf(int k) const;
  Timestamp DepthStampOf(int k) const;
  Rigid3d WorldFromCam(int k) const;
  // Factor the written depth of frame k is multiplied by (options.depth_scale_bias; 1 if off).
  double DepthScaleOf(int k) const;

  // Renders frame k (0 <= k < size()); thread-safe, deterministic.
  SynthFrame Render(int k) const;

  // First stamp of every sequence (seconds).
  static constexpr int64_t kEpochNs = 1000000000LL * 1000000000LL;

 private:
  // Colour image at time t with a rolling shutter (bands of rows from their own poses and people)
  // and motion blur of camera and people: the realistic colour camera before exposure and noise.
  synth::IdealFrame RenderRollingShutter(double t) const;
  // Render's realistic sensor path for frame f.index (stamps and pose already set).
  SynthFrame RenderRealistic(SynthFrame f) const;
  // Instances (boxes, pixel counts, labels) from f's instance mask.
  void FillInstances(SynthFrame* f) const;
  // The world at time t: the scene with the moved object (if any) where it is then.
  const synth::Scene& SceneAt(double t, synth::Scene* storage) const;
  // Where the moved object is at time t, relative to its resting place (metres, world).
  Eigen::Vector3f MovedObjectOffset(double t) const;
  // Seconds from the first frame of a stamp.
  static double SecondsOf(Timestamp stamp) { return (stamp.ns - kEpochNs) * 1e-9; }

  SynthOptions options_;
  int frames_ = 0;
  PinholeCamera camera_;
  synth::Scene scene_;
  std::vector<synth::PersonLook> looks_;
  synth::CameraPath path_;
  synth::PeopleScript people_;
  synth::SensorModel sensor_;
  synth::KinectDepthModel kinect_;
  synth::ColourCameraModel colour_camera_;
  // The realistic sitting preset's laptop on the desk, which a sitting person pushes aside and
  // back (boxes of scene_ with instance moved_instance_, label "laptop"); none elsewhere.
  std::vector<int> moved_boxes_;
  uint16_t moved_instance_ = 0;
  double moved_at_ = 0.0;  // seconds: the push starts (the way back 5 s later)
};

}  // namespace detslam
