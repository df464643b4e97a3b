// The realistic sensor of `detslam synth --realism realistic`: a Kinect-v1-like structured-light
// depth camera and a consumer colour camera, applied to ideal renderings. All randomness is a
// counter-based hash of (seed, frame, pixel or grid node), so results do not depend on the thread
// split. Sources of the numbers: Khoshelham and Elberink, "Accuracy and Resolution of Kinect Depth
// Data" (Sensors 2012: disparity in 1/8 pixel, baseline about 7.5 cm, random error growing with
// the square of the distance); Herrera, Kannala, Heikkila, "Joint depth and color camera calibration
// with distortion correction" (PAMI 2012: a fixed, spatially smooth disparity distortion of each
// device); the missing-depth pattern (registration border, shadow bands beside depth edges, dark
// and grazing surfaces) as seen on the real TUM frames in ../shared/data.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>

#include "detslam/core/camera.h"

namespace detslam::synth {

struct KinectDepthModel {
  // Disparity d = focal * baseline / z (pixels). The projector sits `baseline` to the camera's +x
  // side, so a surface the projector cannot light (a band to the left of every nearer object)
  // gets no depth.
  double baseline = 0.075;          // metres
  double disparity_step = 0.125;    // reported disparity resolution (pixels): 1/8 px
  double sigma_white = 0.04;        // per-pixel disparity noise (pixels)
  double sigma_correlated = 0.05;   // disparity noise shared over cells of `correlation_px`
  int correlation_px = 6;           // about the stereo matcher's window
  double bias_amplitude = 0.06;     // fixed smooth disparity distortion of the device (pixels)
  int bias_cell_px = 96;            // its spatial scale
  double min_depth = 0.45;          // nearer: missing (metres)
  double max_depth = 8.0;           // farther: missing (metres)
  double shadow_tolerance_px = 0.3; // projector occlusion test slack (pixels)
  bool shadows = true;              // false: the projector lights everything (ablations)
  // The depth image registered to the colour camera has no data along its borders (the two
  // cameras' fields of view differ): columns and rows without depth.
  int border_left = 20, border_right = 24, border_top = 10, border_bottom = 8;
  // Depth edges: a pixel whose depth jumps by more than edge_jump + edge_jump_rel * z to a
  // 4-neighbour is missing with probability edge_dropout, else a mixed ("flying") pixel between
  // the two surfaces with probability edge_mixed.
  double edge_jump = 0.04, edge_jump_rel = 0.03;
  double edge_dropout = 0.5, edge_mixed = 0.35;
  // Grazing surfaces: missing with probability rising from 0 at |cos| = grazing_cos_hi to 1 at
  // grazing_cos_lo (cosine between the viewing ray and the surface normal).
  double grazing_cos_lo = 0.15, grazing_cos_hi = 0.36;
  // Weak infrared return (dark matte or glossy surfaces; glass returns nothing): missing with
  // probability rising from 0 at dark_hi to 1 at dark_lo (IdealFrame::ir levels).
  double dark_lo = 15.0, dark_hi = 55.0;
  // Clustered holes: a smooth random field over cells of hole_cell_px, thresholded so that about
  // `hole_fraction` of the pixels fall in holes; plus isolated missing pixels.
  double hole_fraction = 0.03;
  int hole_cell_px = 12;
  double speckle_dropout = 0.005;
};

// 16-bit depth image (metres * camera.depth_map_factor, 0 = missing) of an ideal CV_32F depth
// map (metres, 0 = nothing) rendered at the depth camera's own time, with `infrared` (CV_8U) the
// infrared return of the same rendering (IdealFrame::ir). `device_seed` seeds what stays fixed for
// a device (the disparity distortion), `seed` and `frame` the per-frame noise.
cv::Mat MakeKinectDepth16(const cv::Mat& depth, const cv::Mat& infrared, const PinholeCamera& camera,
                          const KinectDepthModel& model, uint64_t device_seed, uint64_t seed,
                          int frame);

// Pixels (per row, of a CV_32F depth map, metres, 0 = nothing) that a projector `baseline`
// metres to the camera's +x side cannot light: CV_8U, 255 = in shadow.
cv::Mat ProjectorShadow(const cv::Mat& depth, double focal_px, double baseline,
                        double tolerance_px);

struct ColourCameraModel {
  double exposure_s = 0.02;         // exposure time: motion blur of camera and people
  double readout_s = 0.025;         // rolling shutter: first to last row
  int shutter_bands = 30;           // rows rendered per pose: height / bands
  double psf_sigma = 0.8;           // lens and demosaicing softness (pixels, Gaussian)
  double read_sigma = 1.5;          // read noise (grey levels)
  double shot_gain = 0.05;          // photon noise variance per grey level
  double exposure_drift = 0.12;     // auto-exposure gain 1 +- this, drifting over seconds
};

// Auto-exposure gain at time t (seconds): a smooth drift of two slow sinusoids with seeded phases,
// within 1 +- model.exposure_drift.
double ExposureGain(const ColourCameraModel& model, uint64_t seed, double t);

// In place: exposure gain, lens softness (Gaussian PSF) and signal-dependent noise.
void ApplyColourCamera(cv::Mat* bgr, const ColourCameraModel& model, double gain, uint64_t seed,
                       int frame);

// Linear motion blur of the pixels where `mask` is set (CV_8U, dilated by the blur length), from
// `sharp`, written into `out`: a person moving across the image during the exposure.
void BlurRegion(const cv::Mat& sharp, const cv::Mat& mask, cv::Point2f shift_px, cv::Mat* out);

}  // namespace detslam::synth
