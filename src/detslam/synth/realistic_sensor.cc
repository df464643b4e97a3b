#include "detslam/synth/realistic_sensor.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "detslam/synth/hash_noise.h"
#include "detslam/synth/sensor.h"

namespace detslam::synth {
namespace {

constexpr double kTwoPi = 6.283185307179586;

// A smooth standard-normal random field: independent normals at the nodes of a grid of `cell`
// pixels, interpolated bilinearly and renormalised so that every pixel's value is N(0, 1).
// `frame` < 0 gives a field that is the same in every frame. The nodes an image of `width` x
// `height` needs are drawn once, at construction (each node is shared by up to cell^2 pixels);
// a pixel outside the image draws its own (the same values: a node is a function of its key).
class SmoothField {
 public:
  SmoothField(uint64_t seed, int64_t frame, int cell, uint64_t channel, int width, int height)
      : seed_(seed), frame_(static_cast<uint64_t>(frame)), cell_(std::max(1, cell)),
        channel_(channel), cols_(width / cell_ + 2), rows_(height / cell_ + 2) {
    nodes_.resize(static_cast<size_t>(cols_) * rows_);
    for (int j = 0; j < rows_; ++j)
      for (int i = 0; i < cols_; ++i) nodes_[static_cast<size_t>(j) * cols_ + i] = Draw(i, j);
    for (int u = 0; u < width; ++u) columns_.push_back(Cell(u));
    for (int v = 0; v < height; ++v) rows_of_image_.push_back(Cell(v));
  }

  double At(int u, int v) const {
    const auto [i, fx] = u >= 0 && u < static_cast<int>(columns_.size()) ? columns_[u] : Cell(u);
    const auto [j, fy] =
        v >= 0 && v < static_cast<int>(rows_of_image_.size()) ? rows_of_image_[v] : Cell(v);
    const double w[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
    const double n[4] = {Node(i, j), Node(i + 1, j), Node(i, j + 1), Node(i + 1, j + 1)};
    double value = 0, norm = 0;
    for (int k = 0; k < 4; ++k) {
      value += w[k] * n[k];
      norm += w[k] * w[k];
    }
    return value / std::sqrt(norm);
  }

 private:
  // The grid cell of pixel coordinate `c` and the fraction of the way across it.
  std::pair<int64_t, double> Cell(int c) const {
    const double x = (c + 0.5) / cell_;
    const int64_t i = static_cast<int64_t>(std::floor(x));
    return {i, x - i};
  }
  double Node(int64_t i, int64_t j) const {
    if (i >= 0 && i < cols_ && j >= 0 && j < rows_)
      return nodes_[static_cast<size_t>(j) * cols_ + static_cast<size_t>(i)];
    return Draw(i, j);
  }
  double Draw(int64_t i, int64_t j) const {
    const uint64_t node = static_cast<uint64_t>((j + 4096) * 8192 + (i + 4096));
    return HashNormal(HashKey(seed_, frame_, node, channel_));
  }
  uint64_t seed_, frame_;
  int cell_;
  uint64_t channel_;
  int cols_, rows_;
  std::vector<double> nodes_;
  std::vector<std::pair<int64_t, double>> columns_, rows_of_image_;  // Cell() of each u, each v
};

// z such that P(N(0,1) > z) = p, by bisection on erfc (p in (0, 1)).
double UpperNormalQuantile(double p) {
  double lo = -10, hi = 10;
  for (int it = 0; it < 100; ++it) {
    const double mid = 0.5 * (lo + hi);
    if (0.5 * std::erfc(mid / std::sqrt(2.0)) > p) lo = mid; else hi = mid;
  }
  return 0.5 * (lo + hi);
}

double Ramp(double x, double zero_at, double one_at) {
  return std::clamp((x - zero_at) / (one_at - zero_at), 0.0, 1.0);
}

}  // namespace

cv::Mat ProjectorShadow(const cv::Mat& depth, double focal_px, double baseline,
                        double tolerance_px) {
  CV_Assert(depth.type() == CV_32F);
  cv::Mat shadow = cv::Mat::zeros(depth.size(), CV_8U);
  const double fb = focal_px * baseline;
  for (int v = 0; v < depth.rows; ++v) {
    const float* z = depth.ptr<float>(v);
    uchar* s = shadow.ptr<uchar>(v);
    // A point at column u and depth z meets the projector's image at u - fb / z. Scanning from the
    // projector's side, a point is lit only if no point to its right reached a projector column
    // at or left of its own (that nearer point is in front of it along the projector's ray).
    double min_up = std::numeric_limits<double>::infinity();
    for (int u = depth.cols - 1; u >= 0; --u) {
      if (!(z[u] > 0.f)) continue;
      const double up = u - fb / z[u];
      if (up > min_up + tolerance_px) s[u] = 255;
      min_up = std::min(min_up, up);
    }
  }
  return shadow;
}

cv::Mat MakeKinectDepth16(const cv::Mat& depth, const cv::Mat& infrared, const PinholeCamera& camera,
                          const KinectDepthModel& model, uint64_t device_seed, uint64_t seed,
                          int frame) {
  CV_Assert(depth.type() == CV_32F && infrared.type() == CV_8U && infrared.size() == depth.size());
  const int w = depth.cols, h = depth.rows;
  const double fb = camera.fx * model.baseline;
  const uint64_t f = static_cast<uint64_t>(frame);
  const cv::Mat shadow = model.shadows ? ProjectorShadow(depth, camera.fx, model.baseline,
                                                         model.shadow_tolerance_px)
                                        : cv::Mat::zeros(depth.size(), CV_8U);
  const SmoothField bias(device_seed, -1, model.bias_cell_px, 11, w, h);
  const SmoothField correlated(seed, frame, model.correlation_px, 12, w, h);
  // Holes of irregular shape: two scales of random field.
  const SmoothField holes(seed, frame, model.hole_cell_px, 13, w, h);
  const SmoothField hole_detail(seed, frame, std::max(1, model.hole_cell_px / 3), 14, w, h);
  const double hole_level = UpperNormalQuantile(std::clamp(model.hole_fraction, 1e-9, 1 - 1e-9));
  const float fx = static_cast<float>(camera.fx), fy = static_cast<float>(camera.fy);
  const float cx = static_cast<float>(camera.cx), cy = static_cast<float>(camera.cy);
  auto point = [&](int u, int v) {
    const float z = depth.at<float>(v, u);
    return cv::Vec3f((u - cx) / fx * z, (v - cy) / fy * z, z);
  };
  cv::Mat out(depth.size(), CV_16U);
  cv::parallel_for_(cv::Range(0, h), [&](const cv::Range& rows) {
    for (int v = rows.start; v < rows.end; ++v) {
      const float* z = depth.ptr<float>(v);
      uint16_t* o = out.ptr<uint16_t>(v);
      for (int u = 0; u < w; ++u) {
        o[u] = 0;
        double d = z[u];
        const uint64_t pix = static_cast<uint64_t>(v) * w + u;
        if (u < model.border_left || u >= w - model.border_right || v < model.border_top ||
            v >= h - model.border_bottom)
          continue;
        if (!(d >= model.min_depth && d <= model.max_depth)) continue;
        if (shadow.at<uchar>(v, u) != 0) continue;
        if (HashUniform(HashKey(seed, f, pix, 20)) < model.speckle_dropout) continue;
        if ((0.8 * holes.At(u, v) + 0.6 * hole_detail.At(u, v)) > hole_level) continue;
        // Weak infrared return: dark, glossy or glass.
        const double p_dark = 1.0 - Ramp(infrared.at<uchar>(v, u), model.dark_lo, model.dark_hi);
        if (p_dark > 0 && HashUniform(HashKey(seed, f, pix, 21)) < p_dark) continue;
        // Depth edges: missing or mixed between the two surfaces.
        float other = z[u], jump = 0.f;
        const int nu[4] = {u - 1, u + 1, u, u}, nv[4] = {v, v, v - 1, v + 1};
        for (int k = 0; k < 4; ++k) {
          if (nu[k] < 0 || nu[k] >= w || nv[k] < 0 || nv[k] >= h) continue;
          const float zn = depth.at<float>(nv[k], nu[k]);
          const float j = zn > 0.f ? std::abs(zn - z[u]) : 0.f;
          if (j > jump) {
            jump = j;
            other = zn;
          }
        }
        if (jump > model.edge_jump + model.edge_jump_rel * d) {
          const double r = HashUniform(HashKey(seed, f, pix, 22));
          if (r < model.edge_dropout) continue;
          if (r < model.edge_dropout + model.edge_mixed)
            d += (0.2 + 0.6 * HashUniform(HashKey(seed, f, pix, 23))) * (other - d);
        } else if (u > 0 && u + 1 < w && v > 0 && v + 1 < h) {
          // Grazing surfaces: the angle between the viewing ray and the surface normal.
          const float zl = z[u - 1], zr = z[u + 1];
          const float zu = depth.at<float>(v - 1, u), zd = depth.at<float>(v + 1, u);
          if (zl > 0.f && zr > 0.f && zu > 0.f && zd > 0.f) {
            const cv::Vec3f n = (point(u + 1, v) - point(u - 1, v)).cross(point(u, v + 1) -
                                                                           point(u, v - 1));
            const cv::Vec3f ray = point(u, v);
            const double cosine =
                std::abs(n.dot(ray)) / std::max(1e-12, cv::norm(n) * cv::norm(ray));
            const double p_graze =
                1.0 - Ramp(cosine, model.grazing_cos_lo, model.grazing_cos_hi);
            if (p_graze > 0 && HashUniform(HashKey(seed, f, pix, 24)) < p_graze) continue;
          }
        }
        // Disparity: device distortion, correlated and white noise, 1/8-pixel steps.
        double disparity = fb / d + model.bias_amplitude * bias.At(u, v) +
                           model.sigma_correlated * correlated.At(u, v) +
                           model.sigma_white * HashNormal(HashKey(seed, f, pix, 25));
        disparity = std::round(disparity / model.disparity_step) * model.disparity_step;
        if (!(disparity > 0)) continue;
        d = fb / disparity;
        if (!(d >= model.min_depth && d <= model.max_depth)) continue;
        const double q = std::round(d * camera.depth_map_factor);
        o[u] = static_cast<uint16_t>(std::clamp(q, 0.0, 65535.0));
      }
    }
  });
  return out;
}

double ExposureGain(const ColourCameraModel& model, uint64_t seed, double t) {
  const double p1 = kTwoPi * HashUniform(HashKey(seed, 0, 0, 30));
  const double p2 = kTwoPi * HashUniform(HashKey(seed, 0, 0, 31));
  return 1.0 + model.exposure_drift * (0.6 * std::sin(kTwoPi * t / 9.0 + p1) +
                                       0.4 * std::sin(kTwoPi * t / 3.7 + p2));
}

void ApplyColourCamera(cv::Mat* bgr, const ColourCameraModel& model, double gain, uint64_t seed,
                       int frame) {
  CV_Assert(bgr->type() == CV_8UC3);
  cv::Mat img;
  bgr->convertTo(img, CV_32FC3, gain);
  if (model.psf_sigma > 0)
    cv::GaussianBlur(img, img, cv::Size(0, 0), model.psf_sigma, model.psf_sigma,
                     cv::BORDER_REFLECT);
  const int w = img.cols;
  const uint64_t f = static_cast<uint64_t>(frame);
  cv::parallel_for_(cv::Range(0, img.rows), [&](const cv::Range& rows) {
    for (int v = rows.start; v < rows.end; ++v) {
      const cv::Vec3f* in = img.ptr<cv::Vec3f>(v);
      cv::Vec3b* o = bgr->ptr<cv::Vec3b>(v);
      for (int u = 0; u < w; ++u) {
        const uint64_t pix = static_cast<uint64_t>(v) * w + u;
        for (int ch = 0; ch < 3; ++ch) {
          const double level = std::clamp<double>(in[u][ch], 0.0, 255.0);
          const double sigma =
              std::sqrt(model.read_sigma * model.read_sigma + model.shot_gain * level);
          o[u][ch] = cv::saturate_cast<uchar>(in[u][ch] +
                                              sigma * HashNormal(HashKey(seed, f, pix, 32 + ch)));
        }
      }
    }
  });
}

void BlurRegion(const cv::Mat& sharp, const cv::Mat& mask, cv::Point2f shift_px, cv::Mat* out) {
  CV_Assert(mask.type() == CV_8U && mask.size() == sharp.size() && out->size() == sharp.size());
  const cv::Mat kernel = MotionBlurKernel(shift_px);
  if (kernel.empty()) return;
  const cv::Rect box = cv::boundingRect(mask);
  if (box.empty()) return;
  cv::Mat blurred;
  cv::filter2D(sharp(box), blurred, -1, kernel, cv::Point(-1, -1), 0, cv::BORDER_REFLECT);
  blurred.copyTo((*out)(box), mask(box));
}

}  // namespace detslam::synth
