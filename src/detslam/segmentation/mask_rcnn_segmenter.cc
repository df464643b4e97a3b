#include "detslam/segmentation/mask_rcnn_segmenter.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "detslam/core/check.h"
#include "detslam/segmentation/coco_classes.h"
#include "detslam/segmentation/segmenter_settings.h"

namespace detslam {
namespace fs = std::filesystem;

bool MaskRcnnOptions::Check(std::string* error) const {
  std::string e;
  if (graph_path.empty() || config_path.empty() || names_path.empty())
    e = "Mask R-CNN needs a graph (.pb), a config (.pbtxt) and a class names file";
  else if (!(score_threshold > 0 && score_threshold < 1))
    e = "score threshold must be in (0, 1)";
  else if (!(mask_threshold > 0 && mask_threshold < 1))
    e = "mask threshold must be in (0, 1)";
  if (!e.empty() && error != nullptr) *error = e;
  return e.empty();
}

MaskRcnnOptions MaskRcnnOptionsFromSettings(const SegmenterSettings& s, const std::string& models_dir) {
  auto resolve = [&](const std::string& p) {
    if (fs::path(p).is_absolute()) return p;
    return (fs::path(models_dir) / p).string();
  };
  MaskRcnnOptions o = s.maskrcnn;
  o.graph_path = resolve(s.maskrcnn_graph);
  o.config_path = resolve(s.maskrcnn_config);
  o.names_path = resolve(s.maskrcnn_names);
  return o;
}

MaskRcnnSegmenter::MaskRcnnSegmenter(const MaskRcnnOptions& options) : options_(options) {
  std::string error;
  if (!options_.Check(&error)) throw InputError("Mask R-CNN options: " + error);
  const std::vector<std::string> files = {options_.graph_path, options_.config_path,
                                          options_.names_path};
  for (const std::string& p : files) {
    if (fs::is_regular_file(p)) continue;
    std::string all;
    for (const std::string& q : files) {
      all += "\n  " + q + (fs::is_regular_file(q) ? " (found)" : " (MISSING)");
    }
    throw InputError(p, 0,
                     "Mask R-CNN model file not found. Looked for:" + all +
                         "\n(mask_rcnn_inception_v2_coco from the TensorFlow detection model "
                         "zoo with OpenCV's .pbtxt; or use --segmenter dnn)");
  }
  std::ifstream in(options_.names_path);
  std::string line;
  while (std::getline(in, line)) {
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    names_.push_back(line);
  }
  try {
    net_ = cv::dnn::readNetFromTensorflow(options_.graph_path, options_.config_path);
  } catch (const cv::Exception& e) {
    throw InputError(options_.graph_path, 0, std::string("cannot load Mask R-CNN: ") + e.what());
  }
  net_.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  net_.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
}

std::vector<Instance> MaskRcnnSegmenter::Segment(const SegmenterInput& input) {
  if (input.bgr.empty() || input.bgr.type() != CV_8UC3) {
    throw InputError("frame " + input.stamp.ToString() + ": segmenter needs an 8-bit BGR image");
  }
  const cv::Mat blob =
      cv::dnn::blobFromImage(input.bgr, 1.0, cv::Size(), cv::Scalar(), true, false);
  net_.setInput(blob);
  std::vector<cv::Mat> outs;
  net_.forward(outs, std::vector<std::string>{"detection_out_final", "detection_masks"});
  DETSLAM_CHECK(outs.size() == 2 && outs[0].dims == 4 && outs[1].dims == 4);
  const cv::Mat& dets = outs[0];
  const cv::Mat& masks = outs[1];
  const int n = dets.size[2], mask_classes = masks.size[1];
  const int mh = masks.size[2], mw = masks.size[3];
  const cv::Size size = input.bgr.size();
  const cv::Rect image(0, 0, size.width, size.height);
  cv::Mat rows(n, 7, CV_32F, const_cast<float*>(dets.ptr<float>()));
  std::vector<Instance> out;
  for (int i = 0; i < n; ++i) {
    const float score = rows.at<float>(i, 2);
    const int cls = static_cast<int>(rows.at<float>(i, 1));
    if (score < options_.score_threshold || cls < 0 || cls >= mask_classes) continue;
    Instance in;
    in.class_name = cls < static_cast<int>(names_.size()) ? names_[cls] : std::to_string(cls);
    in.class_id = CocoClassId(in.class_name);
    in.score = score;
    const cv::Point tl(static_cast<int>(rows.at<float>(i, 3) * size.width),
                       static_cast<int>(rows.at<float>(i, 4) * size.height));
    const cv::Point br(static_cast<int>(rows.at<float>(i, 5) * size.width),
                       static_cast<int>(rows.at<float>(i, 6) * size.height));
    in.box = cv::Rect(tl, br) & image;
    if (in.box.empty()) continue;
    if (!options_.classes.empty() && std::find(options_.classes.begin(), options_.classes.end(),
                                               in.class_name) == options_.classes.end()) {
      continue;
    }
    cv::Mat small(mh, mw, CV_32F, const_cast<float*>(masks.ptr<float>(i, cls)));
    cv::Mat prob;
    cv::resize(small, prob, in.box.size(), 0, 0, cv::INTER_LINEAR);
    in.mask = cv::Mat(size, CV_8UC1, cv::Scalar(0));
    cv::Mat(prob > options_.mask_threshold).copyTo(in.mask(in.box));
    out.push_back(std::move(in));
  }
  return out;
}

}  // namespace detslam
