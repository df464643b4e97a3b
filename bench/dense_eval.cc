// Scores dense maps (PLY) of a run on a synthetic sequence against the generator's truth
// (synth/dense_truth.h): the run's trajectory.txt poses are aligned to the ground truth's
// (AlignRunToSequence: rigid, orientations included, so that a camera that barely moves still
// fixes the rotation) and that motion moves the clouds into the scene's frame; then, per cloud, the
// fraction of points on people, the point-to-scene distances and the completeness of the static
// surfaces the keyframes saw. bench/bench_dense.sh runs it.
// With --figure OUT.png, the first two clouds are drawn side by side as seen from 0.6 m behind the
// sequence's first camera pose (perspective, z-buffered, their own colours) for the README.
// Usage: dense_eval --preset P --seed S --frames N [--people DIR] --run RUN_DIR --json OUT
//                   [--figure OUT.png] [--smear-dir DIR] NAME=FILE.ply [NAME=FILE.ply ...]
// --smear-dir writes each cloud's points counted as on people to DIR/NAME_smear.ply.
#include <cstdio>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "detslam/core/check.h"
#include "detslam/eval/ate.h"
#include "detslam/io/ply.h"
#include "detslam/io/trajectory.h"
#include "detslam/synth/dense_truth.h"
#include "detslam/synth/sequence.h"

namespace {

// One cloud drawn from `cam_from_world` (640x480, f = 360 px), 2x2 splats, nearest wins.
cv::Mat RenderCloud(const detslam::PointCloud& cloud, const std::vector<Eigen::Vector3d>& world,
                    const detslam::Rigid3d& cam_from_world, const std::string& label) {
  constexpr int kW = 640, kH = 480;
  constexpr double kF = 360.0;
  cv::Mat img(kH, kW, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::Mat zbuf(kH, kW, CV_32FC1, cv::Scalar(1e9f));
  for (size_t i = 0; i < world.size(); ++i) {
    const Eigen::Vector3d c = cam_from_world * world[i];
    if (c.z() < 0.2) continue;
    const int u0 = static_cast<int>(std::lround(kF * c.x() / c.z() + kW / 2.0));
    const int v0 = static_cast<int>(std::lround(kF * c.y() / c.z() + kH / 2.0));
    for (int dv = 0; dv < 2; ++dv) {
      for (int du = 0; du < 2; ++du) {
        const int u = u0 + du, v = v0 + dv;
        if (u < 0 || v < 0 || u >= kW || v >= kH || zbuf.at<float>(v, u) <= c.z()) continue;
        zbuf.at<float>(v, u) = static_cast<float>(c.z());
        const auto& rgb = cloud.colors.empty() ? Eigen::Matrix<uint8_t, 3, 1>(128, 128, 128) : cloud.colors[i];
        img.at<cv::Vec3b>(v, u) = cv::Vec3b(rgb[2], rgb[1], rgb[0]);
      }
    }
  }
  cv::putText(img, label, cv::Point(10, 24), cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(0, 0, 0), 2);
  return img;
}

int Main(int argc, char** argv) {
  using namespace detslam;
  SynthOptions so;
  std::string run_dir, json_path, figure, smear_dir;
  std::vector<std::pair<std::string, std::string>> clouds;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto next = [&]() -> std::string {
      if (i + 1 >= argc) throw InputError(a + " needs a value");
      return argv[++i];
    };
    if (a == "--preset") so.preset = next();
    else if (a == "--seed") so.seed = std::stoull(next());
    else if (a == "--frames") so.frames = std::stoi(next());
    else if (a == "--people") so.people_dir = next();
    else if (a == "--run") run_dir = next();
    else if (a == "--json") json_path = next();
    else if (a == "--figure") figure = next();
    else if (a == "--smear-dir") smear_dir = next();
    else if (a.find('=') != std::string::npos) clouds.emplace_back(a.substr(0, a.find('=')), a.substr(a.find('=') + 1));
    else throw InputError("unknown argument " + a);
  }
  if (run_dir.empty() || json_path.empty() || clouds.empty()) throw InputError("usage: see bench/dense_eval.cc");
  const SyntheticSequence seq(so);
  Trajectory gt;
  for (int k = 0; k < seq.size(); ++k) gt.push_back({seq.StampOf(k), seq.WorldFromCam(k)});
  const Trajectory est = ReadTumTrajectory(run_dir + "/trajectory.txt");
  const AteResult ate = ComputeAte(gt, est, AteOptions());
  const Rigid3d world_from_slam = AlignRunToSequence(seq, est);
  const std::vector<int> keyframes = SequenceFramesOf(seq, ReadTumTrajectory(run_dir + "/keyframes.txt"));
  std::fprintf(stderr, "[dense_eval] %s seed %llu: ATE %.2f mm, %zu keyframes; rendering the truth\n",
               so.preset.c_str(), static_cast<unsigned long long>(so.seed), ate.error_m.rmse * 1e3,
               keyframes.size());
  const DenseTruth truth(seq, keyframes, DenseTruthOptions());
  nlohmann::json out;
  out["preset"] = so.preset;
  out["seed"] = so.seed;
  out["ate_rmse_m"] = ate.error_m.rmse;
  out["keyframes"] = keyframes.size();
  std::vector<cv::Mat> panels;
  const Rigid3d view = Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 0.6)) *
                       seq.WorldFromCam(0).Inverse();
  for (const auto& [name, path] : clouds) {
    const PointCloud cloud = ReadPointCloudPly(path);
    std::vector<Eigen::Vector3d> points = cloud.points;
    for (Eigen::Vector3d& p : points) p = world_from_slam * p;
    if (!figure.empty() && panels.size() < 2) {
      panels.push_back(RenderCloud(cloud, points, view,
                                   name + ": " + std::to_string(points.size() / 1000) + "k points"));
    }
    std::vector<size_t> smear;
    const DenseMapScore s = truth.Score(points, &smear);
    if (!smear_dir.empty()) {  // the points on people, in the run's frame, for diagnosis
      std::vector<Eigen::Vector3d> sp;
      std::vector<Eigen::Matrix<uint8_t, 3, 1>> sc;
      for (const size_t i : smear) {
        sp.push_back(cloud.points[i]);
        if (!cloud.colors.empty()) sc.push_back(cloud.colors[i]);
      }
      WritePointCloudPly(smear_dir + "/" + name + "_smear.ply", sp, sc);
    }
    out["clouds"][name] = {{"points", s.points},
                           {"near_person", s.near_person},
                           {"near_person_fraction", s.NearPersonFraction()},
                           {"smear", s.near_person_off_scene},
                           {"smear_fraction", s.SmearFraction()},
                           {"static_median_m", s.static_median_m},
                           {"static_mean_m", s.static_mean_m},
                           {"static_p90_m", s.static_p90_m},
                           {"static_samples", s.static_samples},
                           {"completeness", s.completeness},
                           {"person_samples", s.person_samples}};
    std::fprintf(stderr, "[dense_eval]   %s: %zu points, %.2f%% near people (%.2f%% off the scene), median %.1f mm, completeness %.1f%%\n",
                 name.c_str(), s.points, 100 * s.NearPersonFraction(), 100 * s.SmearFraction(),
                 s.static_median_m * 1e3, 100 * s.completeness);
  }
  std::ofstream(json_path) << out.dump(1) << "\n";
  if (!figure.empty()) {
    cv::Mat both;
    cv::hconcat(panels, both);
    if (!cv::imwrite(figure, both)) throw InputError(figure, 0, "cannot write the figure");
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return Main(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dense_eval: %s\n", e.what());
    return 1;
  }
}
