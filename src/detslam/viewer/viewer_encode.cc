#include "detslam/viewer/viewer_encode.h"

#include <fmt/format.h>

#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace detslam {
namespace {

// Appends `[v0,v1,...]` with 4 decimals (0.1 mm, 1e-4 px: below what the page can show).
template <typename T>
void AppendNumbers(std::string* out, const T* v, size_t n) {
  out->push_back('[');
  for (size_t i = 0; i < n; ++i) {
    if (i) out->push_back(',');
    const double x = static_cast<double>(v[i]);
    if (std::isfinite(x)) {
      const size_t start = out->size();
      fmt::format_to(std::back_inserter(*out), "{:.4f}", x);
      // No trailing zeros ("12.5000" -> "12.5", "3.0000" -> "3"): a third of the bytes.
      while (out->back() == '0') out->pop_back();
      if (out->back() == '.') out->pop_back();
      if (out->size() - start == 2 && (*out)[start] == '-' && out->back() == '0') out->erase(start, 1);
    } else {
      out->append("null");
    }
  }
  out->push_back(']');
}

// world_from_cam as 12 numbers: the rotation's rows with the translation after each (3x4).
void AppendPose(std::string* out, const Rigid3d& pose) {
  const Eigen::Matrix3d r = pose.RotationMatrix();
  const Eigen::Vector3d t = pose.translation();
  const double m[12] = {r(0, 0), r(0, 1), r(0, 2), t.x(), r(1, 0), r(1, 1),
                        r(1, 2), t.y(),   r(2, 0), r(2, 1), r(2, 2), t.z()};
  AppendNumbers(out, m, 12);
}

void AppendPositions(std::string* out, const std::vector<Eigen::Vector3d>& p) {
  std::vector<double> flat;
  flat.reserve(3 * p.size());
  for (const Eigen::Vector3d& v : p) flat.insert(flat.end(), {v.x(), v.y(), v.z()});
  AppendNumbers(out, flat.data(), flat.size());
}

}  // namespace

std::string CountersJson(const ViewerCounters& c) {
  nlohmann::json j = {{"mode", c.mode},
                      {"state", c.state},
                      {"frame", c.frame},
                      {"frames_done", c.frames_done},
                      {"total", c.total},
                      {"tracked", c.tracked},
                      {"keyframes", c.keyframes},
                      {"points", c.points},
                      {"loops", c.loops},
                      {"merges", c.merges},
                      {"maps", c.maps},
                      {"relocalizations", c.relocalizations},
                      {"fps", std::round(c.fps * 10) / 10},
                      {"pausable", c.pausable},
                      {"paused", c.paused},
                      {"finished", c.finished},
                      {"pages", c.pages},
                      {"seq", c.seq}};
  return j.dump();
}

std::string FrameJson(const ViewerFrame& f) {
  nlohmann::json head = {{"seq", f.seq},
                         {"index", f.index},
                         {"stamp", f.stamp_s},
                         {"state", f.state},
                         {"method", f.method},
                         {"tracked", f.tracked},
                         {"keyframe", f.keyframe},
                         {"skipped", f.skipped},
                         {"inliers", f.inliers},
                         {"dynamic_instances", f.dynamic_instances},
                         {"frame_ms", std::round(f.frame_ms * 10) / 10},
                         {"map_id", f.map_id},
                         {"has_image", !f.bgr.empty()},
                         {"width", f.bgr.cols},
                         {"height", f.bgr.rows}};
  nlohmann::json boxes = nlohmann::json::array();
  for (const cv::Rect& b : f.boxes) boxes.push_back({b.x, b.y, b.width, b.height});
  head["boxes"] = boxes;
  std::string out = head.dump();
  out.pop_back();  // '}': the arrays follow
  out += ",\"pose\":";
  if (f.world_from_cam) {
    AppendPose(&out, *f.world_from_cam);
  } else {
    out += "null";
  }
  out += ",\"keypoints\":";
  if (!f.has_keypoints) {
    out += "null}";
    return out;
  }
  out.push_back('{');
  for (int k = 0; k < kNumKeypointFates; ++k) {
    if (k) out.push_back(',');
    out += fmt::format("\"{}\":", KeypointFateName(static_cast<KeypointFate>(k)));
    AppendNumbers(&out, f.keypoints[k].data(), f.keypoints[k].size());
  }
  out += "}}";
  return out;
}

std::string MapJson(const ViewerMap& m) {
  std::string out = fmt::format("{{\"seq\":{},\"map_id\":{},\"points\":{},\"keyframes\":[", m.seq,
                                m.map_id, m.points.size() / 3);
  for (size_t i = 0; i < m.keyframes.size(); ++i) {
    if (i) out.push_back(',');
    AppendPose(&out, m.keyframes[i]);
  }
  out += "],\"trajectory\":";
  AppendPositions(&out, m.trajectory);
  out += ",\"ground_truth\":";
  AppendPositions(&out, m.ground_truth);
  out.push_back('}');
  return out;
}

std::string MapPointsBinary(const ViewerMap& m) {
  static_assert(sizeof(float) == 4, "float32");
  std::string out(m.points.size() * sizeof(float), '\0');
  // x86 and ARM Linux are little-endian, as the page's Float32Array expects.
  if (!m.points.empty()) std::memcpy(out.data(), m.points.data(), out.size());
  return out;
}

std::string FrameJpeg(const ViewerFrame& f) {
  if (f.bgr.empty()) return "";
  cv::Mat img;
  if (f.bgr.channels() == 1) {
    cv::cvtColor(f.bgr, img, cv::COLOR_GRAY2BGR);
  } else {
    img = f.bgr.clone();  // the snapshot's pixels are shared with the run: never draw on them
  }
  if (!f.masks.empty()) {
    cv::Mat any(img.size(), CV_8UC1, cv::Scalar(0));
    for (const cv::Mat& m : f.masks) {
      if (m.size() == img.size() && m.type() == CV_8UC1) any.setTo(255, m);
    }
    cv::Mat tinted = img.clone();
    tinted.setTo(cv::Scalar(255, 220, 0), any);  // cyan (people's clothes are often red)
    cv::addWeighted(img, 0.55, tinted, 0.45, 0, tinted);
    tinted.copyTo(img, any);
  }
  for (const cv::Rect& b : f.boxes) cv::rectangle(img, b, cv::Scalar(0, 220, 255), 2);
  std::vector<uint8_t> jpeg;
  cv::imencode(".jpg", img, jpeg, {cv::IMWRITE_JPEG_QUALITY, 80});
  return std::string(jpeg.begin(), jpeg.end());
}

}  // namespace detslam
