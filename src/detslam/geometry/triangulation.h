// Two-view triangulation from normalised image coordinates.
#pragma once

#include <Eigen/Core>

#include "detslam/core/rigid3d.h"

namespace detslam {

// Linear (DLT) triangulation: the world point whose projections best match the normalised
// coordinates xn1 = (x/z, y/z) in camera 1 and xn2 in camera 2, via the SVD of the 4x4 system.
// Returns false (leaving *p_world untouched) when the system is degenerate (point at infinity,
// non-finite result) or the point lies behind either camera.
bool TriangulateLinear(const Rigid3d& cam1_from_world, const Rigid3d& cam2_from_world,
                       const Eigen::Vector2d& xn1, const Eigen::Vector2d& xn2,
                       Eigen::Vector3d* p_world);

// Cosine of the angle at p_world between the rays towards the two camera centres
// (1 = no parallax). Returns 1 when the point coincides with a camera centre.
double CosParallax(const Rigid3d& cam1_from_world, const Rigid3d& cam2_from_world,
                   const Eigen::Vector3d& p_world);

// Cosine of the angle between the viewing rays through xn1 and xn2, expressed in the world frame
// (the test ORB-SLAM applies before triangulating a new point).
double CosParallaxRays(const Rigid3d& cam1_from_world, const Rigid3d& cam2_from_world,
                       const Eigen::Vector2d& xn1, const Eigen::Vector2d& xn2);

}  // namespace detslam
