#include "detslam/synth/dense_truth.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_set>

#include "detslam/core/check.h"
#include "detslam/core/grid_key.h"
#include "detslam/geometry/alignment.h"

namespace detslam {
namespace {

double Quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  const size_t k = static_cast<size_t>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

}  // namespace

double SceneSurfaceDistance(const synth::Scene& scene, const Eigen::Vector3d& p) {
  double best = std::numeric_limits<double>::infinity();
  for (const synth::SceneBox& box : scene.boxes) {
    const Eigen::Vector3d lo = box.lo.cast<double>(), hi = box.hi.cast<double>();
    const bool inside = (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all();
    double d;
    if (inside) {  // nearest face from inside (the shell is always seen from here)
      d = std::min((p - lo).minCoeff(), (hi - p).minCoeff());
    } else {
      const Eigen::Vector3d outside = (lo - p).cwiseMax(p - hi).cwiseMax(0.0);
      d = outside.norm();
    }
    best = std::min(best, d);
  }
  return best;
}

namespace {

// For each pose of `trajectory`, the sequence frame at its stamp (to the microsecond) or -1.
std::vector<int> FramesAtStamps(const SyntheticSequence& sequence, const Trajectory& trajectory) {
  const auto micros = [](Timestamp t) { return static_cast<int64_t>(std::llround(t.ns / 1e3)); };
  std::unordered_map<int64_t, int> frame_of_us;
  for (int k = 0; k < sequence.size(); ++k) frame_of_us[micros(sequence.StampOf(k))] = k;
  std::vector<int> frames;
  for (const StampedPose& p : trajectory) {
    const auto it = frame_of_us.find(micros(p.stamp));
    frames.push_back(it == frame_of_us.end() ? -1 : it->second);
  }
  return frames;
}

}  // namespace

std::vector<int> SequenceFramesOf(const SyntheticSequence& sequence, const Trajectory& trajectory) {
  std::vector<int> frames = FramesAtStamps(sequence, trajectory);
  frames.erase(std::remove(frames.begin(), frames.end(), -1), frames.end());
  return frames;
}

Rigid3d AlignRunToSequence(const SyntheticSequence& sequence, const Trajectory& trajectory) {
  const std::vector<int> frames = FramesAtStamps(sequence, trajectory);
  std::vector<Rigid3d> est, gt;
  for (size_t i = 0; i < frames.size(); ++i) {
    if (frames[i] < 0) continue;
    est.push_back(trajectory[i].world_from_cam);
    gt.push_back(sequence.WorldFromCam(frames[i]));
  }
  if (est.empty()) throw InputError("no pose of the trajectory is at a frame of the sequence");
  return AlignPoseSets(est, gt);
}

PointGrid::PointGrid(double cell_m) : cell_(cell_m) { DETSLAM_CHECK(cell_m > 0); }

uint64_t PointGrid::KeyOf(const Eigen::Vector3d& p, Eigen::Vector3i* cell) const {
  const Eigen::Vector3i c = GridCellOf(p, cell_);
  if (cell) *cell = c;
  return GridCellKey(c);
}

void PointGrid::Add(const Eigen::Vector3d& p) {
  cells_[KeyOf(p)].push_back(p.cast<float>());
  ++size_;
}

bool PointGrid::AnyWithin(const Eigen::Vector3d& p, double radius) const {
  DETSLAM_CHECK(radius <= cell_);
  Eigen::Vector3i c;
  KeyOf(p, &c);
  const Eigen::Vector3f q = p.cast<float>();
  const float r2 = static_cast<float>(radius * radius);
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const auto it = cells_.find(GridCellKey(c + Eigen::Vector3i(dx, dy, dz)));
        if (it == cells_.end()) continue;
        for (const Eigen::Vector3f& x : it->second) {
          if ((x - q).squaredNorm() <= r2) return true;
        }
      }
    }
  }
  return false;
}

DenseTruth::DenseTruth(const SyntheticSequence& sequence, const std::vector<int>& keyframes,
                       const DenseTruthOptions& o, const std::function<void(int, int)>& progress)
    : scene_(sequence.scene()), options_(o), people_(o.person_radius_m) {
  DETSLAM_CHECK(o.pixel_step >= 1 && o.person_frame_step >= 1 && o.sample_m > 0);
  const PinholeCamera& cam = sequence.camera();
  const std::unordered_set<int> is_keyframe(keyframes.begin(), keyframes.end());
  std::unordered_set<uint64_t> person_cells, static_cells;  // thinning
  const int n = sequence.size();
  for (int k = 0; k < n; ++k) {
    const bool people_frame = k % o.person_frame_step == 0;
    const bool key = is_keyframe.count(k) > 0;
    if (!people_frame && !key) continue;
    const SynthFrame f = sequence.Render(k);
    for (int v = 0; v < cam.height; v += o.pixel_step) {
      for (int u = 0; u < cam.width; u += o.pixel_step) {
        const float z = f.true_depth.at<float>(v, u);
        if (!(z > 0)) continue;
        const bool person = f.instance_mask.at<uint16_t>(v, u) != 0;
        if (person ? !people_frame : (!key || z < o.min_depth_m || z > o.max_depth_m)) continue;
        const Eigen::Vector3d pw = f.world_from_cam * cam.Unproject(Eigen::Vector2d(u, v), z);
        const uint64_t cell = GridCellKey(GridCellOf(pw, o.sample_m));
        if (person) {
          if (person_cells.insert(cell).second) people_.Add(pw);
        } else if (static_cells.insert(cell).second) {
          statics_.push_back(pw);
        }
      }
    }
    if (progress) progress(k + 1, n);
  }
}

DenseMapScore DenseTruth::Score(const std::vector<Eigen::Vector3d>& points,
                                std::vector<size_t>* smear) const {
  const DenseTruthOptions& o = options_;
  const std::vector<Eigen::Vector3d>& statics = statics_;
  const PointGrid& people = people_;
  DenseMapScore s;
  s.points = points.size();
  s.person_samples = people.size();
  s.static_samples = statics.size();
  std::vector<double> dist;
  dist.reserve(points.size());
  PointGrid cloud(o.completeness_radius_m);
  if (smear) smear->clear();
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d& p = points[i];
    const double d = SceneSurfaceDistance(scene_, p);
    dist.push_back(d);
    if (people.AnyWithin(p, o.person_radius_m)) {
      ++s.near_person;
      if (d > o.off_scene_m) {
        ++s.near_person_off_scene;
        if (smear) smear->push_back(i);
      }
    }
    cloud.Add(p);
  }
  if (!dist.empty()) {
    s.static_median_m = Quantile(dist, 0.5);
    s.static_p90_m = Quantile(dist, 0.9);
    double sum = 0;
    for (const double d : dist) sum += d;
    s.static_mean_m = sum / static_cast<double>(dist.size());
  }
  size_t covered = 0;
  for (const Eigen::Vector3d& p : statics) covered += cloud.AnyWithin(p, o.completeness_radius_m);
  s.completeness = statics.empty() ? 0 : static_cast<double>(covered) / statics.size();
  return s;
}

}  // namespace detslam
