// LocalMapper::TriangulateNewLandmarks: ORB-SLAM3's CreateNewMapPoints for RGB-D keyframes.
// Keypoints of the new keyframe that have no landmark and no close depth (none, or beyond
// ThDepth; close ones already became landmarks from depth) are matched by descriptor with the same
// kind of keypoints of its best covisible keyframes (brute force, ratio 0.6, orientation
// consistency), triangulated (DLT) where the rays have parallax (cos < 0.9998) and the baseline
// exceeds the sensor's, and kept when the point lies in front of both cameras, reprojects within
// the 95% chi2 gate of its keypoint's octave in both (with depth: the RGB-D residual) and its
// distances to the two cameras agree with the two octaves (scale consistency).
#include <cmath>
#include <vector>

#include "detslam/features/matcher.h"
#include "detslam/geometry/projection.h"
#include "detslam/geometry/triangulation.h"
#include "detslam/mapping/local_mapper.h"

namespace detslam {
namespace {

constexpr double kMinCosParallax = 0.9998;
constexpr double kChi2Mono = 5.991;
constexpr double kChi2Stereo = 7.815;

// Keypoints of `kf` that may get a triangulated landmark.
std::vector<int> Candidates(const KeyFrame& kf, double close_depth) {
  std::vector<int> out;
  const FrameFeatures& f = *kf.features;
  for (size_t i = 0; i < kf.size(); ++i) {
    if (kf.landmarks[i] != kNoLandmark) continue;
    if (!kf.labels.empty() && kf.labels[i] != KeypointLabel::kStatic) continue;
    if (f.depth[i] > 0 && f.depth[i] <= close_depth) continue;
    out.push_back(static_cast<int>(i));
  }
  return out;
}

// Keypoints and descriptors of `f` at `indices`, in that order (the matcher's inputs).
void Subset(const FrameFeatures& f, const std::vector<int>& indices, std::vector<cv::KeyPoint>* kps,
            cv::Mat* descriptors) {
  *descriptors = cv::Mat(static_cast<int>(indices.size()), 32, CV_8UC1);
  for (size_t k = 0; k < indices.size(); ++k) {
    kps->push_back(f.keypoints[static_cast<size_t>(indices[k])]);
    f.descriptors.row(indices[k]).copyTo(descriptors->row(static_cast<int>(k)));
  }
}

// The observation's chi2 at `p_world` (with depth: the RGB-D residual).
bool WithinGate(const PinholeCamera& camera, const ScaleInfo& scale, const KeyFrame& kf, size_t i,
                const Eigen::Vector3d& p_world) {
  const FrameFeatures& f = *kf.features;
  const Eigen::Vector3d p_cam = kf.cam_from_world * p_world;
  if (p_cam.z() <= 0) return false;
  const double sqrt_info =
      std::sqrt(scale.inv_level_sigma2[static_cast<size_t>(f.keypoints[i].octave)]);
  const Eigen::Vector3d r =
      WhitenedStereoResidual(camera, p_cam, f.undist[i], f.u_right[i], sqrt_info);
  return f.u_right[i] >= 0 ? r.squaredNorm() <= kChi2Stereo
                           : r.head<2>().squaredNorm() <= kChi2Mono;
}

}  // namespace

void LocalMapper::TriangulateNewLandmarks(MapStore* store, KeyFrameId current,
                                          LocalMappingSummary* summary) {
  const double close_depth = camera_.CloseDepthThreshold();
  MatchOptions match;
  match.ratio = 0.6;
  match.max_distance = kThLow;
  std::vector<KeyFrameId> neighbours;
  double ratio_factor = 0;  // scale consistency: the map's pyramid never changes
  {
    const MapStore::ReadAccess map = store->Read();
    if (!map->HasKeyFrame(current)) return;
    const std::vector<double>& factors = map->scale().scale_factors;
    ratio_factor = 1.5 * (factors.size() > 1 ? factors[1] : 1.2);
    neighbours =
        map->BestCovisibles(current, static_cast<size_t>(options_.triangulation_neighbours));
  }
  // One neighbour at a time, in three steps: its candidates (under the lock), the descriptor
  // matching (the costly part, without it: the features never change), the new landmarks
  // (under the lock again, where every check is made on the map as it is then).
  for (KeyFrameId other : neighbours) {
    std::vector<int> c1, c2;
    std::vector<cv::KeyPoint> kp1, kp2;
    cv::Mat d1, d2;
    {
      const MapStore::ReadAccess map = store->Read();
      if (!map->HasKeyFrame(current) || !map->HasKeyFrame(other)) continue;
      const KeyFrame& kf1 = map->keyframe(current);
      const KeyFrame& kf2 = map->keyframe(other);
      if ((kf1.Center() - kf2.Center()).norm() < camera_.Baseline()) continue;  // too close
      c1 = Candidates(kf1, close_depth);
      c2 = Candidates(kf2, close_depth);
      if (c1.empty() || c2.empty()) continue;
      Subset(*kf1.features, c1, &kp1, &d1);
      Subset(*kf2.features, c2, &kp2, &d2);
    }
    const std::vector<cv::DMatch> matches = MatchBruteForce(kp1, d1, kp2, d2, match);
    const MapStore::WriteAccess access = store->Write();
    Map& map = *access;
    if (!map.HasKeyFrame(current) || !map.HasKeyFrame(other)) continue;
    const ScaleInfo& scale = map.scale();
    const KeyFrame& kf1 = map.keyframe(current);
    const KeyFrame& kf2 = map.keyframe(other);
    const FrameFeatures& f1 = *kf1.features;
    const FrameFeatures& f2 = *kf2.features;
    for (const cv::DMatch& m : matches) {
      const size_t i1 = static_cast<size_t>(c1[static_cast<size_t>(m.queryIdx)]);
      const size_t i2 = static_cast<size_t>(c2[static_cast<size_t>(m.trainIdx)]);
      if (map.keyframe(current).landmarks[i1] != kNoLandmark) continue;  // taken by an earlier pair
      if (map.keyframe(other).landmarks[i2] != kNoLandmark) continue;
      const Eigen::Vector2d xn1 = PixelToNormalized(camera_, f1.undist[i1]);
      const Eigen::Vector2d xn2 = PixelToNormalized(camera_, f2.undist[i2]);
      const double cos_parallax = CosParallaxRays(kf1.cam_from_world, kf2.cam_from_world, xn1, xn2);
      if (!(cos_parallax > 0 && cos_parallax < kMinCosParallax)) continue;
      Eigen::Vector3d p;
      if (!TriangulateLinear(kf1.cam_from_world, kf2.cam_from_world, xn1, xn2, &p)) continue;
      if (!WithinGate(camera_, scale, kf1, i1, p) || !WithinGate(camera_, scale, kf2, i2, p))
        continue;
      // Scale consistency: distance ratio against octave ratio.
      const double dist1 = (p - kf1.Center()).norm(), dist2 = (p - kf2.Center()).norm();
      if (dist1 <= 0 || dist2 <= 0) continue;
      const double ratio_dist = dist2 / dist1;
      const double ratio_octave =
          scale.scale_factors[static_cast<size_t>(f1.keypoints[i1].octave)] /
          scale.scale_factors[static_cast<size_t>(f2.keypoints[i2].octave)];
      if (ratio_dist * ratio_factor < ratio_octave || ratio_dist > ratio_octave * ratio_factor)
        continue;
      const LandmarkId lm = map.AddLandmark(p, current);
      map.AddObservation(lm, current, i1);
      map.AddObservation(lm, other, i2);
      map.UpdateLandmarkDescriptor(lm);
      map.UpdateLandmarkGeometry(lm);
      recent_landmarks_.push_back(lm);
      ++summary->triangulated;
    }
  }
}

}  // namespace detslam
