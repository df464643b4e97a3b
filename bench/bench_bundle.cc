// Bundle adjustment kernel: a local-BA-sized problem (20 optimised keyframes, 20 fixed ones that
// see the same points, about 3000 points, RGB-D keypoints with and without depth) solved by
// SolveBundle with local mapping's 10 Levenberg-Marquardt iterations (single thread).
// Argument: the share of observations without depth (mono) in percent; the realistic generator's
// frames miss depth on about a third of their pixels.
// Usage: detslam_bench_bundle [--benchmark_...]
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

#include "detslam/core/camera.h"
#include "detslam/optim/bundle_adjustment.h"
#include "kernel_bench_main.h"

namespace {

using detslam::BundleProblem;

// Keyframes 6 cm apart along x, turning slowly, looking at points 1-4 m away; each point is
// observed by the keyframes near the one that made it (a track of up to 8) where it projects into
// the image. Observations carry 1 px noise (the disparity its sigma), 5 % are outliers (30 px
// off); the optimised keyframes start 1 cm / 0.3 degrees off, the points 2 cm off.
BundleProblem MakeProblem(int free_poses, int fixed_poses, int points_per_keyframe,
                          double mono_share, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const detslam::PinholeCamera cam;  // 640 x 480, TUM-like intrinsics, bf 40
  BundleProblem p;
  const int num_poses = fixed_poses + free_poses;
  std::vector<detslam::Rigid3d> truth;
  for (int i = 0; i < num_poses; ++i) {
    const Eigen::Quaterniond q(Eigen::AngleAxisd(0.01 * i, Eigen::Vector3d::UnitY()));
    const Eigen::Vector3d centre(0.06 * i, 0.01 * std::sin(0.3 * i), 0.0);
    const detslam::Rigid3d world_from_cam(q, centre);
    truth.push_back(world_from_cam.Inverse());
    BundleProblem::Pose pose;
    pose.id = i;
    pose.fixed = i < fixed_poses;
    pose.cam_from_world = truth.back();
    if (!pose.fixed) {
      const Eigen::Quaterniond dq(Eigen::AngleAxisd(
          0.005, Eigen::Vector3d(n01(rng), n01(rng), n01(rng)).normalized()));
      pose.cam_from_world = detslam::Rigid3d(
          dq * pose.cam_from_world.rotation(),
          pose.cam_from_world.translation() + 0.01 * Eigen::Vector3d(n01(rng), n01(rng), n01(rng)));
    }
    p.poses.push_back(pose);
  }
  for (int i = 0; i < num_poses; ++i) {
    const detslam::Rigid3d world_from_cam = truth[i].Inverse();
    for (int k = 0; k < points_per_keyframe; ++k) {
      const double z = 1.0 + 3.0 * u01(rng);
      const Eigen::Vector3d p_cam((u01(rng) * cam.width - cam.cx) * z / cam.fx,
                                  (u01(rng) * cam.height - cam.cy) * z / cam.fy, z);
      const Eigen::Vector3d p_world = world_from_cam * p_cam;
      std::vector<BundleProblem::Observation> obs;
      for (int j = std::max(0, i - 3); j < std::min(num_poses, i + 5); ++j) {
        const Eigen::Vector3d c = truth[j] * p_world;
        if (c.z() <= 0.1) continue;
        const double u = cam.fx * c.x() / c.z() + cam.cx, v = cam.fy * c.y() / c.z() + cam.cy;
        if (u < 0 || v < 0 || u >= cam.width || v >= cam.height) continue;
        BundleProblem::Observation o;
        o.pose_index = static_cast<size_t>(j);
        const double off = u01(rng) < 0.05 ? 30.0 : 1.0;
        o.uv = Eigen::Vector2d(u + off * n01(rng), v + off * n01(rng));
        if (u01(rng) >= mono_share) {
          o.u_right = o.uv.x() - (cam.bf / c.z() + cam.disparity_sigma * n01(rng));
        }
        const int octave = static_cast<int>(u01(rng) * 4);
        o.inv_sigma2 = 1.0 / std::pow(1.2, 2 * octave);
        obs.push_back(o);
      }
      // Points only the fixed keyframes see are not part of a local BA.
      bool seen_by_free = false;
      for (const auto& o : obs) seen_by_free = seen_by_free || !p.poses[o.pose_index].fixed;
      if (obs.size() < 2 || !seen_by_free) continue;
      BundleProblem::Point point;
      point.id = static_cast<int64_t>(p.points.size());
      point.p_world = p_world + 0.02 * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
      for (auto& o : obs) o.point_index = p.points.size();
      p.points.push_back(point);
      p.observations.insert(p.observations.end(), obs.begin(), obs.end());
    }
  }
  return p;
}

// Arguments: percentage of observations without depth; the solver (BundleOptions::
// dense_schur_max_poses: 0 Ceres's sparse Schur, 64 the hand-written dense Schur, the default).
void BM_LocalBundle(benchmark::State& state) {
  const BundleProblem problem = MakeProblem(20, 20, 120, state.range(0) / 100.0, 7);
  const detslam::PinholeCamera cam;
  detslam::BundleOptions options;
  options.max_iterations = 10;
  options.dense_schur_max_poses = static_cast<int>(state.range(1));
  detslam::BundleSummary summary;
  for (auto _ : state) {
    BundleProblem work = problem;
    summary = detslam::SolveBundle(cam, &work, options);
  }
  state.counters["lm_iterations"] = summary.iterations;
  // The cost reached (0.5 * sum of robustified chi2): the two solvers should agree.
  state.counters["final_cost"] = summary.final_cost;
  state.counters["points"] = static_cast<double>(problem.points.size());
  state.counters["observations"] = static_cast<double>(problem.observations.size());
}
BENCHMARK(BM_LocalBundle)
    ->ArgNames({"no_depth_pct", "dense_schur_max_poses"})
    ->ArgsProduct({{0, 30}, {0, 64}})
    ->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) { return detslam::bench::RunKernelBenchmarks(argc, argv); }
