// Precomputed instance masks on disk (the `masks:DIR` and `gt` segmenter backends), so that a
// sequence is segmented once (by `detslam segment`, the synthetic generator, or any other tool,
// e.g. Detectron2 Mask R-CNN in Python) and run many times.
//
// Format of a masks folder DIR:
//   DIR/<stamp>.png    one instance-id image per colour frame, named by the colour image's
//                      timestamp with 6 decimals (TUM style, e.g. 1341846313.592026.png);
//                      8- or 16-bit single channel, the colour image's size; 0 = no object,
//                      k = pixels of instance k (`detslam segment` writes 16-bit).
//   DIR/<stamp>_<id>.png optional: the whole mask of instance <id> (8-bit, non-zero = object),
//                      used instead of the id image's pixels; `detslam segment` writes it for
//                      masks that overlap another instance's, so that replayed masks are the
//                      segmenter's own (the id image keeps one instance per pixel).
//   DIR/instances.txt  one line per instance, '#' comments, fields separated by spaces:
//                        timestamp id class_id class_name score x y w h
//                      timestamp: colour stamp (as in the PNG name); id: the instance's value in
//                      the PNG (1..65535, unique per frame); class_id: COCO class index
//                      (0 = person); class_name: COCO name with spaces written as '_'
//                      ("traffic_light"); score: confidence in [0, 1]; x y w h: bounding box in
//                      pixels (top-left origin).
//                    The synthetic generator's 8-field form `timestamp id class_name score x y w h`
//                    is read too (class_id from the COCO name, -1 if unknown).
// A frame without a PNG and without lines has no instances; lines without a PNG give box-only
// instances (empty mask). Every id present in a PNG must be listed for that frame.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "detslam/core/timestamp.h"
#include "detslam/segmentation/segmenter.h"

namespace detslam {

// One line of instances.txt.
struct MaskRecord {
  Timestamp stamp;    // colour image stamp
  int id = 0;         // value of the instance's pixels in <stamp>.png
  int class_id = -1;  // COCO class index, -1 unknown
  std::string class_name;
  float score = 1.0f;
  cv::Rect box;
};

// Parses instances.txt (either field layout). Throws InputError with file:line on malformed
// lines, ids outside 1..65535, duplicate ids in a frame, scores outside [0, 1] or negative sizes.
std::map<int64_t, std::vector<MaskRecord>> ReadInstanceList(const std::string& path);

// Path of the mask PNG of a frame: DIR/<stamp with 6 decimals>.png.
std::string MaskPngPath(const std::string& dir, Timestamp stamp);
// Path of one instance's own mask PNG: DIR/<stamp with 6 decimals>_<id>.png.
std::string InstanceMaskPngPath(const std::string& dir, Timestamp stamp, int id);

class MaskDirSegmenter : public Segmenter {
 public:
  // Reads DIR/instances.txt. Throws InputError if DIR or the list is missing or malformed.
  explicit MaskDirSegmenter(const std::string& dir, const std::string& name = "masks");
  // Instances of the frame with stamp input.stamp (input.bgr gives the expected image size; if
  // empty, any size is accepted). Throws InputError naming the PNG if it cannot be read, is not
  // 8/16-bit single channel, has another size than the image, or holds unlisted ids.
  std::vector<Instance> Segment(const SegmenterInput& input) override;
  std::string name() const override { return name_; }
  size_t listed_frames() const { return records_.size(); }

 private:
  std::string dir_, name_;
  std::map<int64_t, std::vector<MaskRecord>> records_;
};

// Writes a masks folder incrementally: Add() writes each frame's PNG at once (atomically, 16-bit,
// only for frames with instances), Finish() writes instances.txt (atomically; also written by
// every Flush() so an interrupted run leaves a consistent folder for the frames done).
class MaskDirWriter {
 public:
  // Creates DIR if needed (InputError if impossible). `header` goes into instances.txt comments.
  explicit MaskDirWriter(const std::string& dir, const std::string& header = "");
  // Instance k (0-based) gets id k + 1; where masks overlap the higher-score instance wins the
  // id image's pixel and the other masks are written whole to their own files, so that reading
  // the folder back gives every mask and score exactly. Instances with an empty mask are written
  // as their box (read back as a box-shaped mask). Masks must be `size` CV_8UC1.
  void Add(Timestamp stamp, const cv::Size& size, const std::vector<Instance>& instances);
  void Flush();
  void Finish() { Flush(); }
  int frames() const { return frames_; }
  int instances() const { return static_cast<int>(lines_.size()); }

 private:
  std::string dir_, header_;
  std::vector<std::string> lines_;
  int frames_ = 0;
};

// One-shot form: writes all frames and the list.
void WriteMasks(const std::string& dir, const std::vector<Timestamp>& stamps,
                const std::vector<std::vector<Instance>>& instances, const cv::Size& size);

}  // namespace detslam
