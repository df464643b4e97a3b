// RGB-D sequences in the TUM RGB-D layout (also used by the Bonn RGB-D Dynamic dataset):
// rgb.txt and depth.txt list `timestamp filename` per line ('#' comments), images are PNGs beside
// them (colour 8-bit, depth 16-bit scaled by DepthMapFactor), groundtruth.txt is optional.
// Colour and depth frames are paired like the TUM tools' associate.py, or from an explicit
// ORB-SLAM-style association file (`ts_rgb rgb_file ts_depth depth_file` per line).
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "detslam/core/camera.h"
#include "detslam/core/timestamp.h"
#include "detslam/io/rgbd_source.h"

namespace detslam {

struct DatasetOptions {
  double max_difference_s = 0.02;  // rgb<->depth association window (TUM associate.py), seconds
  double offset_s = 0.0;           // added to depth stamps before association, seconds
  std::string association_file;    // optional explicit 'ts rgb ts depth' list; relative paths
                                   // resolve against the dataset folder

  bool Check(std::string* error) const;
};

// One associated colour/depth pair; paths are absolute.
struct RgbdFrameRef {
  Timestamp rgb_stamp;
  Timestamp depth_stamp;
  std::string rgb_path;
  std::string depth_path;
};

class RgbdDataset : public RgbdSource {
 public:
  // Reads the lists and associates the frames. Throws InputError (naming the file and line) on a
  // missing folder or list, a malformed line, stamps out of order, a listed image that does not
  // exist, or an empty result.
  static RgbdDataset Open(const std::string& dir, const DatasetOptions& options);

  size_t size() const override { return frames_.size(); }
  Timestamp stamp(size_t i) const override { return frame(i).rgb_stamp; }
  const RgbdFrameRef& frame(size_t i) const;
  const std::vector<RgbdFrameRef>& frames() const { return frames_; }
  const std::string& dir() const { return dir_; }
  const std::string& name() const override { return dir_; }
  // Absolute path of groundtruth.txt, or empty if the folder has none.
  std::string groundtruth_path() const override;

  // Decodes frame i. Colour is converted to 8-bit BGR (grayscale and 4-channel images are
  // converted); depth must be a 16-bit single-channel image of the colour image's size, and both
  // must be camera.width x camera.height. depth_m = value / camera.depth_map_factor. Throws
  // InputError naming the offending image file.
  RgbdImages Load(size_t i, const PinholeCamera& camera) const override;

 private:
  RgbdDataset() = default;

  std::string dir_;
  std::vector<RgbdFrameRef> frames_;
};

}  // namespace detslam
