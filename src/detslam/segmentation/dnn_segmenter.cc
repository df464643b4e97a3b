#include "detslam/segmentation/dnn_segmenter.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <opencv2/dnn.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "detslam/core/check.h"
#include "detslam/segmentation/coco_classes.h"
#include "detslam/segmentation/person_mask.h"
#include "detslam/segmentation/segmenter_settings.h"
#include "detslam/segmentation/yolox_decode.h"

#ifndef DETSLAM_DEFAULT_MODELS_DIR
#define DETSLAM_DEFAULT_MODELS_DIR "models"
#endif

namespace detslam {
namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;
double MsSince(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::string Trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\"'");
  if (a == std::string::npos) return "";
  const size_t b = s.find_last_not_of(" \t\"'");
  return s.substr(a, b - a + 1);
}

std::vector<std::string> ReadNames(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, 0, "cannot open class names file");
  std::vector<std::string> names;
  std::string line;
  while (std::getline(in, line)) {
    const std::string t = Trim(line);
    if (!t.empty()) names.push_back(t);
  }
  if (names.empty()) throw InputError(path, 0, "class names file is empty");
  return names;
}

constexpr const char* kDefaultSecondDetector = "yolo_fastest_1.1/yolo-fastest-1.1-xl.cfg";

std::string DetectorFormatError(const std::string& path, const char* which) {
  if (EndsWith(path, ".onnx") || EndsWith(path, ".cfg")) return "";
  return std::string(which) + " detector must be a YOLOX .onnx or a Darknet .cfg: " + path;
}

}  // namespace

bool DnnSegmenterOptions::Check(std::string* error) const {
  std::string e;
  if (detector_path.empty()) {
    e = "no detector model given";
  } else {
    e = DetectorFormatError(detector_path, "first");
    if (e.empty() && !second_detector_path.empty()) {
      e = DetectorFormatError(second_detector_path, "second");
    }
  }
  if (e.empty()) {
    if (!(score_threshold > 0 && score_threshold < 1))
      e = "score threshold must be in (0, 1)";
    else if (!(second_score_threshold > 0 && second_score_threshold < 1))
      e = "second detector score threshold must be in (0, 1)";
    else if (second_every < 1)
      e = "second detector interval must be at least 1";
    else if (!(nms_threshold > 0 && nms_threshold <= 1))
      e = "NMS threshold must be in (0, 1]";
    else if (!(box_expand >= 0 && box_expand <= 1))
      e = "box expansion must be in [0, 1]";
    else if (yolox_input_size <= 0 || yolox_input_size % 32 != 0)
      e = "YOLOX input size must be a positive multiple of 32";
    else if (darknet_input_size <= 0 || darknet_input_size % 32 != 0)
      e = "Darknet input size must be a positive multiple of 32";
    else if (!(person_mask_threshold > 0 && person_mask_threshold < 1))
      e = "person mask threshold must be in (0, 1)";
    else if (!(person_mask_min_fill >= 0 && person_mask_min_fill < 1))
      e = "person mask minimum fill must be in [0, 1)";
  }
  if (e.empty()) depth_mask.Check(&e);
  if (!e.empty() && error != nullptr) *error = e;
  return e.empty();
}

namespace {

// Darknet weights beside the .cfg; coco.names (body.names for a *_body.cfg) beside the detector.
void ResolveCompanions(const std::string& detector, std::string* weights, std::string* names) {
  if (detector.empty()) return;
  const fs::path det(detector);
  const bool darknet = EndsWith(detector, ".cfg");
  if (darknet && weights->empty()) *weights = fs::path(det).replace_extension(".weights").string();
  if (names->empty()) {
    const bool body = darknet && EndsWith(det.stem().string(), "_body");
    *names = (det.parent_path() / (body ? "body.names" : "coco.names")).string();
  }
}

void AppendModelFiles(const std::string& detector, const std::string& weights,
                      const std::string& names, std::vector<std::string>* paths) {
  paths->push_back(detector);
  if (EndsWith(detector, ".cfg")) paths->push_back(weights);
  paths->push_back(names);
}

}  // namespace

void ResolveModelCompanions(DnnSegmenterOptions* o) {
  ResolveCompanions(o->detector_path, &o->weights_path, &o->names_path);
  ResolveCompanions(o->second_detector_path, &o->second_weights_path, &o->second_names_path);
}

std::vector<std::string> LookedForModels(const DnnSegmenterOptions& options) {
  std::vector<std::string> paths;
  AppendModelFiles(options.detector_path, options.weights_path, options.names_path, &paths);
  if (!options.second_detector_path.empty()) {
    AppendModelFiles(options.second_detector_path, options.second_weights_path,
                     options.second_names_path, &paths);
  }
  if (!options.person_mask_model.empty()) paths.push_back(options.person_mask_model);
  return paths;
}

std::string DefaultModelsDir() {
  const char* env = std::getenv("DETSLAM_MODELS");
  if (env != nullptr && *env != '\0') return env;
  return DETSLAM_DEFAULT_MODELS_DIR;
}

DnnSegmenterOptions DnnOptionsFromSettings(const SegmenterSettings& s, const std::string& models_dir) {
  auto resolve = [&](const std::string& p) {
    if (p.empty() || fs::path(p).is_absolute()) return p;
    return (fs::path(models_dir) / p).string();
  };
  DnnSegmenterOptions o = s.dnn;
  o.detector_path = resolve(s.detector);
  o.weights_path = resolve(s.weights);
  o.names_path = resolve(s.names);
  o.person_mask_model = (s.person_mask == "none" || s.person_mask.empty()) ? "" : resolve(s.person_mask);
  // The default second detector is optional: without its files the first one works alone. A
  // second detector named in the settings must exist.
  if (s.second_detector.empty()) {
    const std::string fallback = resolve(kDefaultSecondDetector);
    if (fs::is_regular_file(fallback)) {
      o.second_detector_path = fallback;
    } else {
      spdlog::warn("second detector {} not found; using the first detector alone", fallback);
    }
  } else if (s.second_detector != "none") {
    o.second_detector_path = resolve(s.second_detector);
  }
  o.second_weights_path = resolve(s.second_weights);
  o.second_names_path = resolve(s.second_names);
  ResolveModelCompanions(&o);
  return o;
}

// One detection network: YOLOX (.onnx) or Darknet (.cfg + .weights) with its class names.
class DnnSegmenter::Detector {
 public:
  Detector(const std::string& path, const std::string& weights, const std::string& names_path,
           float score_threshold, const DnnSegmenterOptions& o)
      : path_(path),
        darknet_(EndsWith(path, ".cfg")),
        names_(ReadNames(names_path)),
        score_threshold_(score_threshold),
        nms_threshold_(o.nms_threshold),
        yolox_side_(o.yolox_input_size) {
    try {
      net_ = darknet_ ? cv::dnn::readNetFromDarknet(path, weights) : cv::dnn::readNetFromONNX(path);
    } catch (const cv::Exception& e) {
      throw InputError(path, 0, std::string("cannot load detector: ") + e.what());
    }
    if (net_.empty()) throw InputError(path, 0, "cannot load detector");
    net_.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
    net_.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
    if (darknet_) {
      darknet_model_ = std::make_unique<cv::dnn::DetectionModel>(net_);
      const int side = o.darknet_input_size;
      darknet_model_->setInputParams(1.0 / 255.0, cv::Size(side, side), cv::Scalar(),
                                     /*swapRB=*/true);
      darknet_model_->setNmsAcrossClasses(false);
    }
  }

  const std::vector<std::string>& names() const { return names_; }

  // Detections sorted by descending score, class ids mapped to names.
  std::vector<Detection> Detect(const cv::Mat& bgr) {
    std::vector<Detection> out;
    for (Detection& d : darknet_ ? DetectDarknet(bgr) : DetectYolox(bgr)) {
      if (d.class_id < 0 || d.class_id >= static_cast<int>(names_.size())) continue;
      d.class_name = names_[d.class_id] == "body" ? "person" : names_[d.class_id];
      out.push_back(std::move(d));
    }
    std::stable_sort(out.begin(), out.end(),
                     [](const Detection& a, const Detection& b) { return a.score > b.score; });
    return out;
  }

 private:
  std::vector<Detection> DetectYolox(const cv::Mat& bgr) {
    double scale = 1.0;
    const cv::Mat boxed = LetterboxTopLeft(bgr, yolox_side_, &scale);
    // NCHW float blob, BGR 0..255, no normalisation.
    cv::Mat blob =
        cv::dnn::blobFromImage(boxed, 1.0, cv::Size(), cv::Scalar(), false, false, CV_32F);
    net_.setInput(blob);
    cv::Mat out = net_.forward();
    const int rows = YoloxOutputRows(yolox_side_);
    if (rows == 0 || out.total() % rows != 0 || out.total() / rows != 5 + names_.size()) {
      std::ostringstream os;
      os << "YOLOX output has " << out.total() << " values; expected " << rows << " x "
         << 5 + names_.size() << " for input size " << yolox_side_ << " and " << names_.size()
         << " classes (set Segmentation.InputSize / Segmentation.Names)";
      throw InputError(path_, 0, os.str());
    }
    const auto raw = DecodeYolox(out.ptr<float>(), rows, static_cast<int>(5 + names_.size()),
                                 yolox_side_, scale, score_threshold_);
    std::vector<Detection> dets;
    for (const RawDetection& d : NmsPerClass(raw, score_threshold_, nms_threshold_)) {
      const cv::Rect box(
          cv::Point(static_cast<int>(std::floor(d.box.x)), static_cast<int>(std::floor(d.box.y))),
          cv::Point(static_cast<int>(std::ceil(d.box.br().x)),
                    static_cast<int>(std::ceil(d.box.br().y))));
      dets.push_back(Detection{"", d.class_id, d.score, box});
    }
    return dets;
  }

  std::vector<Detection> DetectDarknet(const cv::Mat& bgr) {
    std::vector<int> ids;
    std::vector<float> scores;
    std::vector<cv::Rect> boxes;
    darknet_model_->detect(bgr, ids, scores, boxes, score_threshold_, nms_threshold_);
    std::vector<Detection> dets;
    for (size_t i = 0; i < ids.size(); ++i) dets.push_back(Detection{"", ids[i], scores[i], boxes[i]});
    return dets;
  }

  std::string path_;
  bool darknet_;
  std::vector<std::string> names_;
  float score_threshold_;
  float nms_threshold_;
  int yolox_side_;
  cv::dnn::Net net_;
  std::unique_ptr<cv::dnn::DetectionModel> darknet_model_;
};

DnnSegmenter::DnnSegmenter(const DnnSegmenterOptions& options) : options_(options) {
  ResolveModelCompanions(&options_);
  std::string error;
  if (!options_.Check(&error)) throw InputError("segmentation options: " + error);
  const std::vector<std::string> looked = LookedForModels(options_);
  for (const std::string& p : looked) {
    if (fs::is_regular_file(p)) continue;
    std::string all;
    for (const std::string& q : looked) {
      all += "\n  " + q + (fs::is_regular_file(q) ? " (found)" : " (MISSING)");
    }
    throw InputError(p, 0,
                     "model file not found. Looked for:" + all +
                         "\nPut the models there, set $DETSLAM_MODELS or pass --models DIR "
                         "(see models/README.md)");
  }
  const DnnSegmenterOptions& o = options_;
  first_ = std::make_unique<Detector>(o.detector_path, o.weights_path, o.names_path,
                                      o.score_threshold, o);
  if (!o.second_detector_path.empty()) {
    second_ = std::make_unique<Detector>(o.second_detector_path, o.second_weights_path,
                                         o.second_names_path, o.second_score_threshold, o);
  }
  if (!o.person_mask_model.empty()) {
    person_mask_ = std::make_unique<PersonMaskModel>(o.person_mask_model);
  }
  name_ = "dnn:" + fs::path(o.detector_path).filename().string() +
          (second_ ? "+" + fs::path(o.second_detector_path).filename().string() +
                         (o.second_every > 1 ? "(every " + std::to_string(o.second_every) + ")" : "")
                   : "") +
          (person_mask_ ? "+" + fs::path(o.person_mask_model).filename().string() : "");
  spdlog::debug("segmenter {} with {} classes", name_, first_->names().size());
}

DnnSegmenter::~DnnSegmenter() = default;

const std::vector<std::string>& DnnSegmenter::class_names() const { return first_->names(); }

bool DnnSegmenter::Wanted(const std::string& class_name) const {
  return options_.classes.empty() ||
         std::find(options_.classes.begin(), options_.classes.end(), class_name) !=
             options_.classes.end();
}

std::vector<Instance> DnnSegmenter::Segment(const SegmenterInput& input) {
  if (input.bgr.empty() || input.bgr.type() != CV_8UC3) {
    throw InputError("frame " + input.stamp.ToString() + ": segmenter needs an 8-bit BGR image");
  }
  const cv::Size size = input.bgr.size();
  const cv::Rect image(0, 0, size.width, size.height);
  auto t0 = Clock::now();
  // Boxes clipped to the image, of the wanted classes; a box of the second detector only where
  // no same-class box (of the first detector, or one already added) covers half of it.
  std::vector<Detection> dets;
  auto add = [&](Detection& d, bool unless_covered) {
    d.box &= image;
    if (d.box.empty() || !Wanted(d.class_name)) return;
    for (const Detection& k : dets) {
      if (unless_covered && k.class_name == d.class_name && (k.box & d.box).area() * 2 > d.box.area()) return;
    }
    dets.push_back(std::move(d));
  };
  for (Detection& d : first_->Detect(input.bgr)) add(d, false);
  const size_t from_first = dets.size();
  timings_.second_ran = false;
  if (second_) {
    if (calls_ % options_.second_every == 0) {
      second_last_ = second_->Detect(input.bgr);
      timings_.second_ran = true;
    }
    for (Detection d : second_last_) add(d, true);
  }
  ++calls_;
  timings_.second_added = static_cast<int>(dets.size() - from_first);
  timings_.detect_ms = MsSince(t0);
  t0 = Clock::now();
  std::vector<Instance> out;
  for (const Detection& d : dets) {
    Instance in;
    in.box = d.box;
    in.class_name = d.class_name;
    const int coco = CocoClassId(in.class_name);
    in.class_id = coco >= 0 ? coco : d.class_id;
    in.score = d.score;
    if (in.class_id == 0 && person_mask_) {
      const cv::Rect crop = ExpandBox(in.box, options_.box_expand, size);
      in.mask = PersonMaskOrDepth(
          person_mask_->Mask(input.bgr, crop, options_.person_mask_threshold), in.box,
          options_.person_mask_min_fill, input.depth_m, options_.depth_mask);
    } else {
      in.mask = DominantDepthBoxMask(input.depth_m, in.box, size, options_.depth_mask);
    }
    out.push_back(std::move(in));
  }
  timings_.mask_ms = MsSince(t0);
  return out;
}

}  // namespace detslam

namespace detslam {

void DnnSegmenter::WarmUp(const SegmenterInput& input) {
  const int64_t calls = calls_;
  calls_ = 0;  // the second detector runs too
  const std::vector<Instance> found = Segment(input);
  const bool person = std::any_of(found.begin(), found.end(),
                                  [](const Instance& i) { return i.class_id == 0; });
  if (person_mask_ && !person && !input.bgr.empty()) {
    const cv::Size size = input.bgr.size();
    person_mask_->Mask(input.bgr, cv::Rect(size.width / 4, size.height / 4, size.width / 2, size.height / 2));
  }
  calls_ = calls;
  second_last_.clear();
  timings_ = DnnTimings();
}

}  // namespace detslam
