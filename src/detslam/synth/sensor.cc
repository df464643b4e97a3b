#include "detslam/synth/sensor.h"

#include <algorithm>
#include <cmath>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "detslam/synth/hash_noise.h"

namespace detslam::synth {

cv::Mat MakeDepth16(const cv::Mat& depth, const PinholeCamera& camera, const SensorModel& model,
                    uint64_t seed, int frame, bool noise) {
  CV_Assert(depth.type() == CV_32F);
  cv::Mat out(depth.size(), CV_16U);
  const int w = depth.cols, h = depth.rows;
  const uint64_t f = static_cast<uint64_t>(frame);
  cv::parallel_for_(cv::Range(0, h), [&](const cv::Range& rows) {
    for (int v = rows.start; v < rows.end; ++v) {
      const float* z = depth.ptr<float>(v);
      uint16_t* o = out.ptr<uint16_t>(v);
      for (int u = 0; u < w; ++u) {
        double d = z[u];
        if (!(d >= model.min_depth && d <= model.max_depth)) {
          o[u] = 0;
          continue;
        }
        if (noise) {
          const uint64_t pix = static_cast<uint64_t>(v) * w + u;
          // Depth discontinuity: the largest jump to a 4-neighbour.
          float jump = 0.f;
          if (u > 0) jump = std::max(jump, std::abs(z[u] - z[u - 1]));
          if (u + 1 < w) jump = std::max(jump, std::abs(z[u] - z[u + 1]));
          if (v > 0) jump = std::max(jump, std::abs(z[u] - depth.ptr<float>(v - 1)[u]));
          if (v + 1 < h) jump = std::max(jump, std::abs(z[u] - depth.ptr<float>(v + 1)[u]));
          if (jump > model.edge_jump + model.edge_jump_rel * d &&
              HashUniform(HashKey(seed, f, pix, 1)) < model.edge_dropout) {
            o[u] = 0;
            continue;
          }
          const uint64_t block = static_cast<uint64_t>(v / 2) * w + u / 2;
          if (HashUniform(HashKey(seed, f, pix, 2)) < 0.5 * model.random_dropout ||
              HashUniform(HashKey(seed, f, block, 3)) < 0.5 * model.random_dropout) {
            o[u] = 0;
            continue;
          }
          const double dz = d - model.z_offset;
          d += (model.sigma0 + model.sigma2 * dz * dz) * HashNormal(HashKey(seed, f, pix, 4));
        }
        const double q = std::round(d * camera.depth_map_factor);
        o[u] = static_cast<uint16_t>(std::clamp(q, 0.0, 65535.0));
      }
    }
  });
  return out;
}

void AddColourNoise(cv::Mat* bgr, const SensorModel& model, uint64_t seed, int frame) {
  CV_Assert(bgr->type() == CV_8UC3);
  const int w = bgr->cols;
  const uint64_t f = static_cast<uint64_t>(frame);
  cv::parallel_for_(cv::Range(0, bgr->rows), [&](const cv::Range& rows) {
    for (int v = rows.start; v < rows.end; ++v) {
      cv::Vec3b* p = bgr->ptr<cv::Vec3b>(v);
      for (int u = 0; u < w; ++u) {
        const uint64_t pix = static_cast<uint64_t>(v) * w + u;
        for (int ch = 0; ch < 3; ++ch) {
          const double n = model.colour_sigma * HashNormal(HashKey(seed, f, pix, 5 + ch));
          p[u][ch] = cv::saturate_cast<uchar>(p[u][ch] + n);
        }
      }
    }
  });
}

cv::Mat MotionBlurKernel(cv::Point2f shift_px) {
  const float len = std::hypot(shift_px.x, shift_px.y);
  if (!(len >= 0.75f)) return cv::Mat();
  const int half = static_cast<int>(std::ceil(len / 2.0f));
  const int size = 2 * half + 1;
  cv::Mat kernel = cv::Mat::zeros(size, size, CV_32F);
  const int steps = std::max(2, static_cast<int>(std::ceil(len * 2.0f)));
  for (int i = 0; i <= steps; ++i) {
    const float s = static_cast<float>(i) / steps - 0.5f;
    const int x = half + static_cast<int>(std::lround(s * shift_px.x));
    const int y = half + static_cast<int>(std::lround(s * shift_px.y));
    kernel.at<float>(y, x) += 1.f;
  }
  kernel /= cv::sum(kernel)[0];
  return kernel;
}

void ApplyMotionBlur(cv::Mat* bgr, cv::Point2f shift_px) {
  const cv::Mat kernel = MotionBlurKernel(shift_px);
  if (kernel.empty()) return;
  cv::filter2D(*bgr, *bgr, -1, kernel, cv::Point(-1, -1), 0, cv::BORDER_REFLECT);
}

}  // namespace detslam::synth
