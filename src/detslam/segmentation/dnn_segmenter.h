// The OpenCV-dnn (CPU) segmenter: a COCO detector (YOLOX ONNX, or Yolo-Fastest Darknet cfg +
// weights) finds boxes; an optional second detector adds the boxes the first one missed (a box of
// the second is kept when no box of the same class from the first covers half of it); person
// boxes get a MediaPipe Selfie Segmentation mask computed on the box expanded by `box_expand`,
// replaced by the depth mask below when it fills less than `person_mask_min_fill` of the box (the
// portrait model misses close-up bodies without a face); other classes get the box pixels at the
// object's dominant depth (box_mask.h). Models: ../shared/models/README.md (or $DETSLAM_MODELS).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "detslam/segmentation/box_mask.h"
#include "detslam/segmentation/segmenter.h"

namespace detslam {

class PersonMaskModel;

struct DnnSegmenterOptions {
  std::string detector_path;         // .onnx (YOLOX) or .cfg (Darknet, with weights_path)
  std::string weights_path;          // Darknet weights; empty = detector path with .weights
  std::string names_path;            // class names, one per line; empty = coco.names beside the
                                     // detector (body.names for a *_body.cfg)
  std::string person_mask_model;     // selfie_segmentation.onnx; empty = box (depth) masks only
  float score_threshold = 0.35f;     // minimum detection score (obj * class for YOLOX)
  float nms_threshold = 0.45f;       // IoU above which same-class boxes are suppressed
  double box_expand = 0.10;          // person box grown by this fraction per side for the mask crop
  std::vector<std::string> classes;  // class names to return; empty = all
  int yolox_input_size = 416;        // square input of the YOLOX export (multiple of 32)
  int darknet_input_size = 320;      // square input of the Darknet model
  float person_mask_threshold = 0.5f;  // selfie probability above which a pixel is person
  float person_mask_min_fill = 0.25f;  // selfie mask covering less of the box -> depth mask
  // Optional second detector (same formats as the first; empty = none). Its boxes are added where
  // the first detector found nothing of that class.
  std::string second_detector_path;
  std::string second_weights_path;
  std::string second_names_path;
  float second_score_threshold = 0.15f;
  // The second detector runs on every `second_every`-th Segment() call (the first, then every
  // N-th); the calls between reuse its last boxes (people move a few pixels per frame; the masks
  // are still computed on the current image). 1 = every call.
  int second_every = 2;
  DominantDepthOptions depth_mask;     // masks of classes without a mask model

  bool Check(std::string* error) const;
};

// Fills empty weights_path / names_path from the detector path (see the field comments).
void ResolveModelCompanions(DnnSegmenterOptions* options);

// Every model file the options need (detector, weights for Darknet, names, person mask model),
// after ResolveModelCompanions.
std::vector<std::string> LookedForModels(const DnnSegmenterOptions& options);

// Models folder: $DETSLAM_MODELS if set, else the build's default (<shared>/models).
std::string DefaultModelsDir();

struct SegmenterSettings;

// Options from the settings (segmenter_settings.h; `detslam settings --list` describes the keys):
// relative paths resolve against models_dir; weights and names default to the files beside the
// detector; an empty second detector means yolo-fastest-1.1-xl when its file exists in
// models_dir, "none" no second detector; person mask "none" means box (depth) masks only.
DnnSegmenterOptions DnnOptionsFromSettings(const SegmenterSettings& settings, const std::string& models_dir);

// Time spent by the last Segment() call.
struct DnnTimings {
  double detect_ms = 0;  // preprocessing + network + decoding + NMS
  double mask_ms = 0;    // person masks and depth masks of all instances
  int second_added = 0;  // boxes added by the second detector
  bool second_ran = false;  // the second detector ran in this call (else its last boxes were used)
};

class DnnSegmenter : public Segmenter {
 public:
  // Loads the networks. Throws InputError if the options are invalid or a model file is missing
  // (the message names the missing file and every path looked at) or unreadable.
  explicit DnnSegmenter(const DnnSegmenterOptions& options);
  ~DnnSegmenter() override;

  std::vector<Instance> Segment(const SegmenterInput& input) override;
  std::string name() const override { return name_; }
  // Both detectors and the person mask model once on `input` (the mask model on a box in the
  // middle when no person is found); the call counter and the second detector's boxes are reset.
  void WarmUp(const SegmenterInput& input) override;
  const DnnTimings& last_timings() const { return timings_; }
  // Class names of the first detector.
  const std::vector<std::string>& class_names() const;

 private:
  struct Detection {
    std::string class_name;  // "body" (person-only models) reported as "person"
    int class_id;            // index in the detector's names file
    float score;
    cv::Rect box;
  };
  class Detector;
  bool Wanted(const std::string& class_name) const;

  DnnSegmenterOptions options_;
  std::string name_;
  std::unique_ptr<Detector> first_;
  std::unique_ptr<Detector> second_;
  std::vector<Detection> second_last_;  // the second detector's boxes from its last run
  int64_t calls_ = 0;                   // Segment() calls so far
  std::unique_ptr<PersonMaskModel> person_mask_;
  DnnTimings timings_;
};

}  // namespace detslam
