// Where a run's RGB-D frames come from: a TUM-layout folder (RgbdDataset) or a ROS 1 bag
// (RosbagSource). The runner sees only this interface: a fixed list of associated frames, each
// with its colour stamp, decoded on demand.
#pragma once

#include <opencv2/core.hpp>
#include <string>

#include "detslam/core/camera.h"
#include "detslam/core/timestamp.h"

namespace detslam {

struct RgbdImages {
  cv::Mat bgr;      // CV_8UC3, OpenCV channel order
  cv::Mat gray;     // CV_8UC1
  cv::Mat depth_m;  // CV_32FC1, metres, 0 = missing
};

// "640x480": an image size in messages.
std::string ImageSizeText(int width, int height);

// A decoded 8-bit image (OpenCV order: grey, BGR or BGRA) as BGR; an empty Mat for another
// channel count (the caller names the file in its error).
cv::Mat DecodedToBgr(const cv::Mat& decoded);

class RgbdSource {
 public:
  virtual ~RgbdSource() = default;

  // Number of associated colour/depth frames.
  virtual size_t size() const = 0;
  // Stamp of frame i's colour image (the stamp its pose gets in trajectory.txt).
  virtual Timestamp stamp(size_t i) const = 0;
  // Decodes frame i for `camera` (whose size the images must have). Throws InputError naming the
  // file (and, for a bag, the topic and stamp) when the frame cannot be read; callers may skip it.
  // Called from one thread at a time.
  virtual RgbdImages Load(size_t i, const PinholeCamera& camera) const = 0;
  // What the frames were read from (a folder or a bag file), for logs and outputs.
  virtual const std::string& name() const = 0;
  // A TUM-format ground-truth file for these frames, or empty when there is none.
  virtual std::string groundtruth_path() const = 0;
};

}  // namespace detslam
