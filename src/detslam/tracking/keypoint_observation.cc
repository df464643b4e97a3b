#include "detslam/tracking/keypoint_observation.h"

namespace detslam {

PoseObservation KeypointObservation(const FrameFeatures& f, size_t i,
                                    const Eigen::Vector3d& point_world, const ScaleInfo& scale) {
  PoseObservation o;
  o.point_world = point_world;
  o.uv = f.undist[i];
  o.u_right = f.u_right[i];
  o.inv_sigma2 = scale.inv_level_sigma2[static_cast<size_t>(f.keypoints[i].octave)];
  return o;
}

}  // namespace detslam
