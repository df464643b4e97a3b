// Writes a synthetic sequence to disk in the TUM RGB-D layout:
//   rgb/<stamp>.png  depth/<stamp>.png (16-bit, metres * 5000, 0 = missing)  rgb.txt depth.txt
//   groundtruth.txt (TUM, world_from_camera per frame)  masks/<stamp>.png (16-bit instance ids)
//   masks/instances.txt  settings.yaml (ORB-SLAM3 v1.0 style, TUM fr3 camera)
// Every file is written atomically; the same options give byte-identical files. With a cut
// (options.cut_begin/cut_end) the cut frames are absent from every file and folder (the rest keep
// their true stamps and poses: a gap in time, a jump in pose).
#pragma once

#include <opencv2/core.hpp>
#include <string>

#include "detslam/synth/options.h"

namespace detslam {

// What writing a sequence measured.
struct SynthStats {
  int frames = 0;                // frames written
  double render_seconds = 0;     // time spent rendering (scene, people, sensor effects)
  double total_seconds = 0;      // rendering + PNG encoding + writing files
  double render_fps = 0;         // frames / render_seconds
  double total_fps = 0;          // frames / total_seconds
  double mean_fast_corners = 0;  // mean cv::FAST (threshold 20, non-max) corners, sampled frames
  double mean_coverage = 0;      // mean fraction of pixels covered by people, all frames
  double mean_missing_depth = 0; // mean fraction of pixels without depth, sampled frames
  int sampled_frames = 0;        // frames the FAST count and missing depth were taken on
};

// Renders and writes the sequence into `out_dir` (created if missing; existing files of the same
// names are replaced). Throws InputError on invalid options, bad people cut-outs or unwritable
// output. Logs progress every 50 frames.
SynthStats WriteSequence(const SynthOptions& options, const std::string& out_dir);

// Number of FAST corners (threshold 20, non-max suppression) in a BGR image.
int CountFastCorners(const cv::Mat& bgr);

// Fraction of the pixels of a depth image (any single-channel type) that are 0 (missing).
double MissingDepthFraction(const cv::Mat& depth);

}  // namespace detslam
