#include "detslam/map/frame.h"

#include <algorithm>
#include <cmath>

#include "detslam/core/check.h"

namespace detslam {

ScaleInfo ScaleInfo::Geometric(double scale_factor, int num_levels) {
  ScaleInfo s;
  for (int l = 0; l < num_levels; ++l) {
    const double f = std::pow(scale_factor, l);
    s.scale_factors.push_back(f);
    s.level_sigma2.push_back(f * f);
    s.inv_level_sigma2.push_back(1.0 / (f * f));
  }
  s.log_scale_factor = std::log(scale_factor);
  return s;
}

ImageBounds UndistortedBounds(const PinholeCamera& camera) {
  ImageBounds b{0.0, static_cast<double>(camera.width), 0.0, static_cast<double>(camera.height)};
  if (!camera.HasDistortion()) return b;
  const double w = camera.width, h = camera.height;
  const std::vector<Eigen::Vector2d> c = camera.Undistort({{0, 0}, {w, 0}, {0, h}, {w, h}});
  b.min_x = std::min(c[0].x(), c[2].x());
  b.max_x = std::max(c[1].x(), c[3].x());
  b.min_y = std::min(c[0].y(), c[1].y());
  b.max_y = std::max(c[2].y(), c[3].y());
  return b;
}

std::shared_ptr<const KeypointGrid> MakeKeypointGrid(const PinholeCamera& camera,
                                                     const std::vector<cv::KeyPoint>& keypoints,
                                                     const std::vector<Eigen::Vector2d>& undist) {
  std::vector<int> octaves(keypoints.size());
  for (size_t i = 0; i < keypoints.size(); ++i) octaves[i] = keypoints[i].octave;
  return std::make_shared<KeypointGrid>(undist, octaves, UndistortedBounds(camera));
}

std::vector<float> SampleKeypointDepth(const std::vector<cv::KeyPoint>& keypoints,
                                       const cv::Mat& depth_m) {
  std::vector<float> depth(keypoints.size(), -1.0f);
  for (size_t i = 0; i < keypoints.size(); ++i) {
    const int u = static_cast<int>(std::lround(keypoints[i].pt.x));
    const int v = static_cast<int>(std::lround(keypoints[i].pt.y));
    if (depth_m.empty() || u < 0 || v < 0 || u >= depth_m.cols || v >= depth_m.rows) continue;
    const float d = depth_m.at<float>(v, u);
    if (d > 0 && std::isfinite(d)) depth[i] = d;
  }
  return depth;
}

std::shared_ptr<FrameFeatures> BuildFrameFeatures(const PinholeCamera& camera,
                                                  std::vector<cv::KeyPoint> keypoints,
                                                  cv::Mat descriptors, std::vector<float> depth) {
  DETSLAM_CHECK_MSG(depth.size() == keypoints.size(),
                    depth.size() << " depths for " << keypoints.size() << " keypoints");
  auto f = std::make_shared<FrameFeatures>();
  const size_t n = keypoints.size();
  std::vector<Eigen::Vector2d> distorted(n);
  for (size_t i = 0; i < n; ++i) distorted[i] = {keypoints[i].pt.x, keypoints[i].pt.y};
  f->undist = camera.Undistort(distorted);
  f->depth = std::move(depth);
  f->u_right.assign(n, -1.0f);
  for (size_t i = 0; i < n; ++i) {
    const float d = f->depth[i];
    if (d > 0) f->u_right[i] = static_cast<float>(f->undist[i].x() - camera.bf / d);
  }
  f->grid = MakeKeypointGrid(camera, keypoints, f->undist);
  f->keypoints = std::move(keypoints);
  f->descriptors = std::move(descriptors);
  return f;
}

void ComputeFrameBow(const Vocabulary& vocabulary, FrameFeatures* features) {
  features->bow = vocabulary.Transform(features->descriptors, &features->bow_nodes,
                                       vocabulary.levels() - kDirectIndexDepth);
}

}  // namespace detslam
