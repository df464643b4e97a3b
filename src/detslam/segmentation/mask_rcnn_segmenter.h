// Mask R-CNN (the paper's segmenter) through OpenCV dnn: the TensorFlow Object Detection API's
// mask_rcnn_inception_v2_coco frozen graph with its OpenCV .pbtxt (readNetFromTensorflow), outputs
// detection_out_final (1x1xNx7: batch, class, score, left, top, right, bottom in 0..1) and
// detection_masks (N x classes x 15 x 15). UNTESTED here: no Mask R-CNN weights are available on
// the development machines; only the missing-file errors are tested.
#pragma once

#include <opencv2/dnn.hpp>
#include <string>
#include <vector>

#include "detslam/segmentation/segmenter.h"

namespace detslam {

struct MaskRcnnOptions {
  std::string graph_path;            // frozen_inference_graph.pb
  std::string config_path;           // OpenCV's mask_rcnn_inception_v2_coco_2018_01_28.pbtxt
  std::string names_path;            // class names, line k = network class id k (90-class TF list)
  float score_threshold = 0.5f;      // minimum detection score
  float mask_threshold = 0.3f;       // mask probability above which a pixel belongs to the object
  std::vector<std::string> classes;  // class names to return; empty = all

  bool Check(std::string* error) const;
};

struct SegmenterSettings;

// Options from the settings (Segmentation.MaskRcnnGraph, .MaskRcnnConfig, .MaskRcnnNames: relative
// paths resolve against models_dir; Segmentation.ScoreThreshold; Dynamic.Classes).
MaskRcnnOptions MaskRcnnOptionsFromSettings(const SegmenterSettings& settings,
                                            const std::string& models_dir);

class MaskRcnnSegmenter : public Segmenter {
 public:
  // Throws InputError naming every missing file, or an unreadable model.
  explicit MaskRcnnSegmenter(const MaskRcnnOptions& options);
  std::vector<Instance> Segment(const SegmenterInput& input) override;
  std::string name() const override { return "maskrcnn"; }

 private:
  MaskRcnnOptions options_;
  std::vector<std::string> names_;
  cv::dnn::Net net_;
};

}  // namespace detslam
