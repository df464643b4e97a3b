// The segmenters' settings as typed values (Segmentation.* keys and Dynamic.Classes; declared,
// parsed and range-checked once in pipeline/settings_keys.cc). Paths are as written: relative ones
// resolve against the models folder when the backend's options are built
// (DnnOptionsFromSettings, MaskRcnnOptionsFromSettings).
#pragma once

#include <string>
#include <vector>

#include "detslam/segmentation/dnn_segmenter.h"
#include "detslam/segmentation/mask_rcnn_segmenter.h"
#include "detslam/segmentation/segmenter.h"

namespace detslam {

struct SegmenterSettings {
  std::string detector = "yolox_nano/yolox_nano.onnx";  // first detector (.onnx or Darknet .cfg)
  std::string weights;  // Darknet weights; empty: beside the detector
  std::string names;    // class names; empty: coco.names beside the detector
  std::string person_mask = "selfie_segmentation/selfie_segmentation.onnx";  // "none": box masks
  std::string second_detector;  // empty: yolo-fastest-1.1-xl when found; "none": one detector
  std::string second_weights;   // Darknet weights of the second detector; empty: beside it
  std::string second_names;     // class names of the second detector; empty: beside it
  std::string maskrcnn_graph = "mask_rcnn_inception_v2_coco/frozen_inference_graph.pb";
  std::string maskrcnn_config =
      "mask_rcnn_inception_v2_coco/mask_rcnn_inception_v2_coco_2018_01_28.pbtxt";
  std::string maskrcnn_names = "mask_rcnn_inception_v2_coco/object_detection_classes_coco.txt";
  DnnSegmenterOptions dnn;   // thresholds, sizes, classes (its paths are filled from the above)
  // The YOLOX input side in the camera-rate mode (--realtime), in place of dnn.yolox_input_size:
  // a smaller input makes the detector faster and the masks the frames get fresher (see
  // ForCameraRate).
  int camera_rate_input_size = 256;
  MaskRcnnOptions maskrcnn;  // score threshold, classes (its paths are filled from the above)

  // The segmenters return only the dynamic classes: Dynamic.Classes sets them with the filter's,
  // and its default is theirs too. Masks of the other classes would be computed for nothing.
  SegmenterSettings() { dnn.classes = maskrcnn.classes = DefaultDynamicClasses(); }
};

// The settings a camera-rate run (--realtime) segments with: YOLOX input camera_rate_input_size.
SegmenterSettings ForCameraRate(SegmenterSettings settings);

}  // namespace detslam
