// Ground truth for the dense static map of a synthetic sequence (bench/bench_dense.sh): the
// static scene's surfaces (exact: the room's boxes), where the people were (their rendered
// surfaces in every frame) and which static surfaces the keyframes saw, and the score of a dense
// point cloud against them.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <unordered_map>
#include <vector>

#include "detslam/io/trajectory.h"
#include "detslam/synth/scene.h"
#include "detslam/synth/sequence.h"

namespace detslam {

// Distance (metres) from `p` (world) to the nearest face of the scene's boxes (the room shell is
// seen from inside; furniture from outside).
double SceneSurfaceDistance(const synth::Scene& scene, const Eigen::Vector3d& p);

// Points hashed into cubic cells, for "is any point within r" queries (r <= the cell size).
class PointGrid {
 public:
  explicit PointGrid(double cell_m);
  void Add(const Eigen::Vector3d& p);
  // True if a point lies within `radius` (<= cell size, CHECK) of `p`.
  bool AnyWithin(const Eigen::Vector3d& p, double radius) const;
  size_t size() const { return size_; }

 private:
  uint64_t KeyOf(const Eigen::Vector3d& p, Eigen::Vector3i* cell = nullptr) const;
  double cell_;
  size_t size_ = 0;
  std::unordered_map<uint64_t, std::vector<Eigen::Vector3f>> cells_;
};

struct DenseTruthOptions {
  double person_radius_m = 0.10;        // a point this close to a person's surface is "on a person"
  double off_scene_m = 0.03;            // ... and counts as a smear when this far from the scene
  double completeness_radius_m = 0.02;  // a seen static sample is covered by a point this close
  double sample_m = 0.01;      // person and static samples: at most one per cell of this size
  int pixel_step = 2;          // pixels between samples in each image direction
  int person_frame_step = 1;   // people of every k-th frame
  double min_depth_m = 0.3;    // static samples: the fusion's depth range
  double max_depth_m = 4.0;
};

struct DenseMapScore {
  size_t points = 0;
  size_t near_person = 0;            // within person_radius_m of a person's surface at any time
  size_t near_person_off_scene = 0;  //   and farther than off_scene_m from every static surface
  double static_median_m = 0, static_mean_m = 0, static_p90_m = 0;  // point-to-scene distances
  size_t static_samples = 0;  // static surface samples the keyframes saw (in the depth range)
  double completeness = 0;    // fraction of them with a point within completeness_radius_m
  size_t person_samples = 0;
  double NearPersonFraction() const { return points ? static_cast<double>(near_person) / points : 0; }
  double SmearFraction() const {
    return points ? static_cast<double>(near_person_off_scene) / points : 0;
  }
};

// Frame indices of the poses of `trajectory` (stamps of the sequence's frames, to the
// microsecond; other stamps are left out), in the trajectory's order.
std::vector<int> SequenceFramesOf(const SyntheticSequence& sequence, const Trajectory& trajectory);

// world_from_slam: the rigid motion that best maps a run's poses (trajectory.txt) onto the
// sequence's ground truth, orientations included (AlignPoseSets; well defined also for a camera
// that barely moves). Throws InputError when no stamp of `trajectory` is a frame of the sequence.
Rigid3d AlignRunToSequence(const SyntheticSequence& sequence, const Trajectory& trajectory);

// The truth of one sequence, built once (it renders the frames) and used to score any number of
// clouds: its people over every person_frame_step-th frame, its static surfaces as seen from
// `keyframes` (frame indices). Keeps a reference to the sequence's scene.
class DenseTruth {
 public:
  DenseTruth(const SyntheticSequence& sequence, const std::vector<int>& keyframes,
             const DenseTruthOptions& options,
             const std::function<void(int done, int total)>& progress = nullptr);
  // Scores `points` (world frame of the sequence, i.e. already aligned). With `smear`, the indices
  // of the points counted in near_person_off_scene are stored there (for diagnosis).
  DenseMapScore Score(const std::vector<Eigen::Vector3d>& points,
                      std::vector<size_t>* smear = nullptr) const;

 private:
  const synth::Scene& scene_;
  DenseTruthOptions options_;
  PointGrid people_;
  std::vector<Eigen::Vector3d> statics_;
};

}  // namespace detslam
