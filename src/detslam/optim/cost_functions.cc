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

}  // namespace detslam
