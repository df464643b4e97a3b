// The only place the reprojection functors are instantiated for autodiff (keeps compile time low).
#include "detslam/optim/cost_functions.h"

#include <ceres/autodiff_cost_function.h>

namespace detslam {

ceres::CostFunction* StereoReprojectionCost::Create(const StereoIntrinsics& k,
                                                    const Eigen::Vector3d& observed_uvr,
                                                    double sqrt_info) {
  return new ceres::AutoDiffCostFunction<StereoReprojectionCost, 3, 4, 3, 3>(
      new StereoReprojectionCost(k, observed_uvr, sqrt_info));
}

ceres::CostFunction* MonoReprojectionCost::Create(const StereoIntrinsics& k,
                                                  const Eigen::Vector2d& observed_uv,
                                                  double sqrt_info) {
  return new ceres::AutoDiffCostFunction<MonoReprojectionCost, 2, 4, 3, 3>(
      new MonoReprojectionCost(k, observed_uv, sqrt_info));
}

ceres::CostFunction* PoseOnlyStereoCost::Create(const StereoIntrinsics& k,
                                                const Eigen::Vector3d& observed_uvr,
                                                const Eigen::Vector3d& point_world,
                                                double sqrt_info) {
  return new ceres::AutoDiffCostFunction<PoseOnlyStereoCost, 3, 4, 3>(
      new PoseOnlyStereoCost(k, observed_uvr, point_world, sqrt_info));
}

ceres::CostFunction* PoseOnlyMonoCost::Create(const StereoIntrinsics& k,
                                              const Eigen::Vector2d& observed_uv,
                                              const Eigen::Vector3d& point_world,
                                              double sqrt_info) {
  return new ceres::AutoDiffCostFunction<PoseOnlyMonoCost, 2, 4, 3>(
      new PoseOnlyMonoCost(k, observed_uv, point_world, sqrt_info));
}

}  // namespace detslam
