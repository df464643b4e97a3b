#include "detslam/io/dataset.h"

#include <spdlog/spdlog.h>

#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "detslam/core/association.h"
#include "detslam/core/check.h"
#include "detslam/io/text_lines.h"

namespace detslam {
namespace fs = std::filesystem;
namespace {

struct ListedImage {
  Timestamp stamp;
  std::string path;  // absolute
};

std::string ResolveAgainst(const std::string& dir, const std::string& name) {
  const fs::path p(name);
  return (p.is_absolute() ? p : fs::path(dir) / p).lexically_normal().string();
}

Timestamp ParseStampField(const std::string& list, int line, const std::string& text) {
  Timestamp t;
  if (!ParseTimestamp(text, &t)) throw InputError(list, line, "malformed timestamp '" + text + "'");
  return t;
}

// Throws unless `stamp` comes strictly after `previous` (the stamp on `previous_line`).
void CheckOrder(const std::string& list, int line, Timestamp stamp, Timestamp previous,
                int previous_line) {
  if (previous_line > 0 && !(previous < stamp)) {
    throw InputError(list, line,
                     "timestamp " + stamp.ToString() + " is not after " + previous.ToString() +
                         " on line " + std::to_string(previous_line) +
                         " (stamps must be strictly increasing)");
  }
}

void CheckImageExists(const std::string& list, int line, const std::string& image) {
  std::error_code ec;  // e.g. a name too long for the file system: an input error, not a crash
  if (!fs::is_regular_file(image, ec)) {
    throw InputError(list, line,
                     "listed image file does not exist: " + image +
                         (ec ? " (" + ec.message() + ")" : std::string()));
  }
}

// Reads a TUM image list (rgb.txt / depth.txt).
std::vector<ListedImage> ReadImageList(const std::string& dir, const std::string& list) {
  if (!fs::is_regular_file(list)) {
    throw InputError(list, 0, "image list missing (expected the TUM RGB-D layout in " + dir + ")");
  }
  std::vector<ListedImage> images;
  int previous_line = 0;
  ForEachDataLine(list, [&](int line, const std::vector<std::string>& fields) {
    if (fields.size() != 2) {
      throw InputError(
          list, line,
          "expected 2 fields 'timestamp filename', got " + std::to_string(fields.size()));
    }
    ListedImage image{ParseStampField(list, line, fields[0]), ResolveAgainst(dir, fields[1])};
    if (!images.empty()) CheckOrder(list, line, image.stamp, images.back().stamp, previous_line);
    CheckImageExists(list, line, image.path);
    images.push_back(std::move(image));
    previous_line = line;
  });
  return images;
}

// Reads an explicit association file: `ts_rgb rgb_file ts_depth depth_file [more columns]`.
std::vector<RgbdFrameRef> ReadAssociationFile(const std::string& dir, const std::string& list) {
  if (!fs::is_regular_file(list)) throw InputError(list, 0, "association file missing");
  std::vector<RgbdFrameRef> frames;
  int previous_line = 0;
  ForEachDataLine(list, [&](int line, const std::vector<std::string>& fields) {
    if (fields.size() < 4) {
      throw InputError(list, line,
                       "expected at least 4 fields 'ts_rgb rgb_file ts_depth depth_file', got " +
                           std::to_string(fields.size()));
    }
    RgbdFrameRef f;
    f.rgb_stamp = ParseStampField(list, line, fields[0]);
    f.rgb_path = ResolveAgainst(dir, fields[1]);
    f.depth_stamp = ParseStampField(list, line, fields[2]);
    f.depth_path = ResolveAgainst(dir, fields[3]);
    if (!frames.empty())
      CheckOrder(list, line, f.rgb_stamp, frames.back().rgb_stamp, previous_line);
    CheckImageExists(list, line, f.rgb_path);
    CheckImageExists(list, line, f.depth_path);
    frames.push_back(std::move(f));
    previous_line = line;
  });
  return frames;
}

std::string DescribeMat(const cv::Mat& m) {
  std::ostringstream os;
  os << m.cols << "x" << m.rows << ", " << m.channels() << " channel(s), "
     << (m.depth() == CV_8U    ? "8-bit"
         : m.depth() == CV_16U ? "16-bit"
                               : "other depth type");
  return os.str();
}

}  // namespace

bool DatasetOptions::Check(std::string* error) const {
  std::string e;
  if (!(max_difference_s > 0)) e += "max_difference_s must be positive; ";
  if (!std::isfinite(offset_s)) e += "offset_s must be finite; ";
  if (error != nullptr) *error = e;
  return e.empty();
}

RgbdDataset RgbdDataset::Open(const std::string& dir, const DatasetOptions& options) {
  std::string error;
  if (!options.Check(&error)) throw InputError(dir, 0, "invalid dataset options: " + error);
  if (!fs::exists(dir)) throw InputError(dir, 0, "dataset folder does not exist");
  if (!fs::is_directory(dir)) throw InputError(dir, 0, "dataset path is not a folder");

  RgbdDataset dataset;
  dataset.dir_ = fs::absolute(dir).lexically_normal().string();
  if (dataset.dir_.size() > 1 && dataset.dir_.back() == '/') dataset.dir_.pop_back();

  if (!options.association_file.empty()) {
    const std::string list = ResolveAgainst(dataset.dir_, options.association_file);
    dataset.frames_ = ReadAssociationFile(dataset.dir_, list);
    if (dataset.frames_.empty()) throw InputError(list, 0, "association file lists no frames");
    spdlog::info("{}: {} frames from association file {}", dataset.dir_, dataset.frames_.size(),
                 list);
    return dataset;
  }

  const std::string rgb_list = (fs::path(dataset.dir_) / "rgb.txt").string();
  const std::string depth_list = (fs::path(dataset.dir_) / "depth.txt").string();
  const std::vector<ListedImage> rgb = ReadImageList(dataset.dir_, rgb_list);
  const std::vector<ListedImage> depth = ReadImageList(dataset.dir_, depth_list);
  if (rgb.empty()) throw InputError(rgb_list, 0, "lists no images (empty sequence)");
  if (depth.empty()) throw InputError(depth_list, 0, "lists no images (empty sequence)");

  std::vector<Timestamp> rgb_stamps, depth_stamps;
  for (const ListedImage& image : rgb) rgb_stamps.push_back(image.stamp);
  for (const ListedImage& image : depth) depth_stamps.push_back(image.stamp);
  AssociationOptions assoc;
  assoc.max_difference_s = options.max_difference_s;
  assoc.offset_s = options.offset_s;
  const auto pairs = AssociateTimestamps(rgb_stamps, depth_stamps, assoc);
  if (pairs.empty()) {
    std::ostringstream os;
    os << "no colour image has a depth image within " << options.max_difference_s << " s (offset "
       << options.offset_s << " s); nothing associated between " << rgb_list << " (" << rgb.size()
       << " images) and " << depth_list << " (" << depth.size() << " images)";
    throw InputError(dataset.dir_, 0, os.str());
  }
  for (const auto& [i, j] : pairs) {
    dataset.frames_.push_back({rgb[i].stamp, depth[j].stamp, rgb[i].path, depth[j].path});
  }
  spdlog::info("{}: associated {} of {} colour and {} depth images (window {} s)", dataset.dir_,
               pairs.size(), rgb.size(), depth.size(), options.max_difference_s);
  return dataset;
}

const RgbdFrameRef& RgbdDataset::frame(size_t i) const {
  DETSLAM_CHECK_MSG(i < frames_.size(), "frame " << i << " of " << frames_.size());
  return frames_[i];
}

std::string RgbdDataset::groundtruth_path() const {
  const fs::path gt = fs::path(dir_) / "groundtruth.txt";
  return fs::is_regular_file(gt) ? gt.string() : std::string();
}

RgbdImages RgbdDataset::Load(size_t i, const PinholeCamera& camera) const {
  const RgbdFrameRef& f = frame(i);
  RgbdImages out;

  const cv::Mat colour = cv::imread(f.rgb_path, cv::IMREAD_UNCHANGED);
  if (colour.empty()) throw InputError(f.rgb_path, 0, "cannot decode colour image");
  if (colour.depth() != CV_8U) {
    throw InputError(f.rgb_path, 0, "colour image must be 8-bit, got " + DescribeMat(colour));
  }
  out.bgr = DecodedToBgr(colour);
  if (out.bgr.empty()) {
    throw InputError(f.rgb_path, 0, "unsupported colour image: " + DescribeMat(colour));
  }
  if (out.bgr.cols != camera.width || out.bgr.rows != camera.height) {
    throw InputError(f.rgb_path, 0,
                     "colour image is " + ImageSizeText(out.bgr.cols, out.bgr.rows) +
                         " but the camera settings say " + ImageSizeText(camera.width, camera.height));
  }
  // OpenCV decodes PNG/JPEG into BGR order regardless of Camera.RGB, so the conversion is fixed.
  cv::cvtColor(out.bgr, out.gray, cv::COLOR_BGR2GRAY);

  const cv::Mat depth = cv::imread(f.depth_path, cv::IMREAD_ANYDEPTH | cv::IMREAD_ANYCOLOR);
  if (depth.empty()) throw InputError(f.depth_path, 0, "cannot decode depth image");
  if (depth.type() != CV_16UC1) {
    throw InputError(f.depth_path, 0,
                     "depth image must be 16-bit single-channel, got " + DescribeMat(depth));
  }
  if (depth.size() != out.bgr.size()) {
    throw InputError(f.depth_path, 0,
                     "depth image is " + ImageSizeText(depth.cols, depth.rows) +
                         " but its colour image " + f.rgb_path + " is " +
                         ImageSizeText(out.bgr.cols, out.bgr.rows));
  }
  if (!(camera.depth_map_factor > 0)) {
    throw InputError(f.depth_path, 0, "camera DepthMapFactor must be positive to convert depth");
  }
  depth.convertTo(out.depth_m, CV_32F, 1.0 / camera.depth_map_factor);
  return out;
}

}  // namespace detslam
