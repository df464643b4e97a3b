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

}  // namespace

struct DnnSegmenter::Nets {
  cv::dnn::Net net;
  std::unique_ptr<cv::dnn::DetectionModel> darknet;
};

bool DnnSegmenterOptions::Check(std::string* error) const {
  std::string e;
  if (detector_path.empty())
    e = "no detector model given";
  else if (!EndsWith(detector_path, ".onnx") && !EndsWith(detector_path, ".cfg"))
    e = "detector must be a YOLOX .onnx or a Darknet .cfg: " + detector_path;
  else if (!(score_threshold > 0 && score_threshold < 1))
    e = "score threshold must be in (0, 1)";
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
  if (e.empty()) depth_mask.Check(&e);
  if (!e.empty() && error != nullptr) *error = e;
  return e.empty();
}

void ResolveModelCompanions(DnnSegmenterOptions* o) {
  const fs::path det(o->detector_path);
  const bool darknet = EndsWith(o->detector_path, ".cfg");
  if (darknet && o->weights_path.empty()) {
    o->weights_path = fs::path(det).replace_extension(".weights").string();
  }
  if (o->names_path.empty()) {
    const bool body = darknet && EndsWith(det.stem().string(), "_body");
    o->names_path = (det.parent_path() / (body ? "body.names" : "coco.names")).string();
  }
}

std::vector<std::string> LookedForModels(const DnnSegmenterOptions& options) {
  std::vector<std::string> paths = {options.detector_path};
  if (EndsWith(options.detector_path, ".cfg")) paths.push_back(options.weights_path);
  paths.push_back(options.names_path);
  if (!options.person_mask_model.empty()) paths.push_back(options.person_mask_model);
  return paths;
}

std::string DefaultModelsDir() {
  const char* env = std::getenv("DETSLAM_MODELS");
  if (env != nullptr && *env != '\0') return env;
  return DETSLAM_DEFAULT_MODELS_DIR;
}

DnnSegmenterOptions DnnOptionsFromSettings(const Settings& s, const std::string& models_dir) {
  auto resolve = [&](const std::string& p) {
    if (p.empty() || fs::path(p).is_absolute()) return p;
    return (fs::path(models_dir) / p).string();
  };
  DnnSegmenterOptions o;
  o.detector_path = resolve(s.GetString("Segmentation.Detector", "yolox_nano/yolox_nano.onnx"));
  o.weights_path = resolve(s.GetString("Segmentation.Weights", ""));
  o.names_path = resolve(s.GetString("Segmentation.Names", ""));
  const std::string mask =
      s.GetString("Segmentation.PersonMask", "selfie_segmentation/selfie_segmentation.onnx");
  o.person_mask_model = (mask == "none" || mask.empty()) ? "" : resolve(mask);
  o.score_threshold =
      static_cast<float>(s.GetDouble("Segmentation.ScoreThreshold", o.score_threshold));
  o.nms_threshold = static_cast<float>(s.GetDouble("Segmentation.NmsThreshold", o.nms_threshold));
  o.box_expand = s.GetDouble("Segmentation.BoxExpand", o.box_expand);
  o.yolox_input_size = s.GetInt("Segmentation.InputSize", o.yolox_input_size);
  std::stringstream classes(s.GetString("Segmentation.DynamicClasses", ""));
  std::string item;
  while (std::getline(classes, item, ',')) {
    if (!Trim(item).empty()) o.classes.push_back(Trim(item));
  }
  ResolveModelCompanions(&o);
  return o;
}

DnnSegmenter::DnnSegmenter(const DnnSegmenterOptions& options)
    : options_(options), nets_(std::make_unique<Nets>()) {
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
  darknet_ = EndsWith(options_.detector_path, ".cfg");
  names_ = ReadNames(options_.names_path);
  try {
    if (darknet_) {
      nets_->net = cv::dnn::readNetFromDarknet(options_.detector_path, options_.weights_path);
    } else {
      nets_->net = cv::dnn::readNetFromONNX(options_.detector_path);
    }
  } catch (const cv::Exception& e) {
    throw InputError(options_.detector_path, 0, std::string("cannot load detector: ") + e.what());
  }
  if (nets_->net.empty()) throw InputError(options_.detector_path, 0, "cannot load detector");
  nets_->net.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  nets_->net.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
  if (darknet_) {
    nets_->darknet = std::make_unique<cv::dnn::DetectionModel>(nets_->net);
    const int s = options_.darknet_input_size;
    nets_->darknet->setInputParams(1.0 / 255.0, cv::Size(s, s), cv::Scalar(), /*swapRB=*/true);
    nets_->darknet->setNmsAcrossClasses(false);
  }
  if (!options_.person_mask_model.empty()) {
    person_mask_ = std::make_unique<PersonMaskModel>(options_.person_mask_model);
  }
  name_ = "dnn:" + fs::path(options_.detector_path).filename().string() +
          (person_mask_ ? "+" + fs::path(options_.person_mask_model).filename().string() : "");
  spdlog::debug("segmenter {} with {} classes", name_, names_.size());
}

DnnSegmenter::~DnnSegmenter() = default;

std::vector<DnnSegmenter::Detection> DnnSegmenter::DetectYolox(const cv::Mat& bgr) {
  const int side = options_.yolox_input_size;
  double scale = 1.0;
  const cv::Mat boxed = LetterboxTopLeft(bgr, side, &scale);
  // NCHW float blob, BGR 0..255, no normalisation.
  cv::Mat blob = cv::dnn::blobFromImage(boxed, 1.0, cv::Size(), cv::Scalar(), false, false, CV_32F);
  nets_->net.setInput(blob);
  cv::Mat out = nets_->net.forward();
  const int rows = YoloxOutputRows(side);
  if (rows == 0 || out.total() % rows != 0 || out.total() / rows != 5 + names_.size()) {
    std::ostringstream os;
    os << "YOLOX output has " << out.total() << " values; expected " << rows << " x "
       << 5 + names_.size() << " for input size " << side << " and " << names_.size()
       << " classes (set Segmentation.InputSize / Segmentation.Names)";
    throw InputError(options_.detector_path, 0, os.str());
  }
  const auto raw = DecodeYolox(out.ptr<float>(), rows, static_cast<int>(5 + names_.size()), side,
                               scale, options_.score_threshold);
  std::vector<Detection> dets;
  for (const RawDetection& d : NmsPerClass(raw, options_.score_threshold, options_.nms_threshold)) {
    const cv::Rect box(
        cv::Point(static_cast<int>(std::floor(d.box.x)), static_cast<int>(std::floor(d.box.y))),
        cv::Point(static_cast<int>(std::ceil(d.box.br().x)),
                  static_cast<int>(std::ceil(d.box.br().y))));
    dets.push_back({d.class_id, d.score, box});
  }
  return dets;
}

std::vector<DnnSegmenter::Detection> DnnSegmenter::DetectDarknet(const cv::Mat& bgr) {
  std::vector<int> ids;
  std::vector<float> scores;
  std::vector<cv::Rect> boxes;
  nets_->darknet->detect(bgr, ids, scores, boxes, options_.score_threshold, options_.nms_threshold);
  std::vector<Detection> dets;
  for (size_t i = 0; i < ids.size(); ++i) dets.push_back({ids[i], scores[i], boxes[i]});
  std::stable_sort(dets.begin(), dets.end(),
                   [](const Detection& a, const Detection& b) { return a.score > b.score; });
  return dets;
}

std::vector<Instance> DnnSegmenter::Segment(const SegmenterInput& input) {
  if (input.bgr.empty() || input.bgr.type() != CV_8UC3) {
    throw InputError("frame " + input.stamp.ToString() + ": segmenter needs an 8-bit BGR image");
  }
  const cv::Size size = input.bgr.size();
  const cv::Rect image(0, 0, size.width, size.height);
  auto t0 = Clock::now();
  const std::vector<Detection> dets = darknet_ ? DetectDarknet(input.bgr) : DetectYolox(input.bgr);
  timings_.detect_ms = MsSince(t0);
  t0 = Clock::now();
  std::vector<Instance> out;
  for (const Detection& d : dets) {
    Instance in;
    in.box = d.box & image;
    if (in.box.empty() || d.class_id < 0 || d.class_id >= static_cast<int>(names_.size())) continue;
    in.class_name = names_[d.class_id] == "body" ? "person" : names_[d.class_id];
    const int coco = CocoClassId(in.class_name);
    in.class_id = coco >= 0 ? coco : d.class_id;
    in.score = d.score;
    if (!options_.classes.empty() && std::find(options_.classes.begin(), options_.classes.end(),
                                               in.class_name) == options_.classes.end()) {
      continue;
    }
    if (in.class_id == 0 && person_mask_) {
      const cv::Rect crop = ExpandBox(in.box, options_.box_expand, size);
      in.mask = person_mask_->Mask(input.bgr, crop, options_.person_mask_threshold);
    } else {
      in.mask = DominantDepthBoxMask(input.depth_m, in.box, size, options_.depth_mask);
    }
    out.push_back(std::move(in));
  }
  timings_.mask_ms = MsSince(t0);
  return out;
}

}  // namespace detslam
