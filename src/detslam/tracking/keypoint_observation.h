// The pose optimiser's observation of one frame keypoint, shared by tracking and loop closing.
#pragma once

#include <Eigen/Core>
#include <cstddef>

#include "detslam/map/frame.h"
#include "detslam/optim/pose_optimizer.h"

namespace detslam {

// Keypoint `i` of `f` seeing `point_world`: its undistorted position, its virtual right coordinate
// (depth) and the information scale of its pyramid level.
PoseObservation KeypointObservation(const FrameFeatures& f, size_t i,
                                    const Eigen::Vector3d& point_world, const ScaleInfo& scale);

}  // namespace detslam
