// Kinect-like sensor effects applied to an ideal rendering: axial depth noise, quantisation to the
// depth PNG scale, missing depth (range limits, depth discontinuities, random dropouts), colour
// noise and optional motion blur. All randomness is a counter-based hash of
// (seed, frame, pixel), so results do not depend on the thread split.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>

#include "detslam/core/camera.h"

namespace detslam::synth {

struct SensorModel {
  // Axial depth noise sigma(z) = sigma0 + sigma2 * (z - z_offset)^2 metres: the Kinect v1 model of
  // Nguyen, Izadi, Lovell, "Modeling Kinect Sensor Noise for Improved 3D Reconstruction and
  // Tracking" (3DIMPVT 2012), for surfaces facing the sensor.
  double sigma0 = 0.0012;            // metres
  double sigma2 = 0.0019;            // metres per square metre
  double z_offset = 0.4;             // metres
  double min_depth = 0.4;            // nearer is missing (0), metres
  double max_depth = 4.5;            // farther is missing (0), metres
  double random_dropout = 0.02;      // fraction of pixels randomly missing (in 1- and 2x2 clusters)
  double edge_jump = 0.04;           // depth jump (metres, + edge_jump_rel * z) counted as an edge
  double edge_jump_rel = 0.03;       // relative part of the jump threshold
  double edge_dropout = 0.8;         // probability that a pixel at a depth edge is missing
  double colour_sigma = 2.0;         // Gaussian colour noise (gray levels)
};

// 16-bit depth image (metres * camera.depth_map_factor, 0 = missing) from a CV_32F depth map.
// With `noise` false only the range limits and quantisation are applied.
cv::Mat MakeDepth16(const cv::Mat& depth, const PinholeCamera& camera, const SensorModel& model,
                    uint64_t seed, int frame, bool noise);

// Adds Gaussian colour noise in place.
void AddColourNoise(cv::Mat* bgr, const SensorModel& model, uint64_t seed, int frame);

// Kernel of a linear motion blur along `shift_px` (pixels moved during the exposure), normalised;
// empty if the motion is shorter than 0.75 px (no visible blur).
cv::Mat MotionBlurKernel(cv::Point2f shift_px);

// Linear motion blur in place: the image moved by `shift_px` (pixels) during the exposure.
void ApplyMotionBlur(cv::Mat* bgr, cv::Point2f shift_px);

}  // namespace detslam::synth
