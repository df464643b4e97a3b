#include "detslam/io/rosbag_source.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "detslam/core/association.h"
#include "detslam/core/check.h"

namespace detslam {
namespace {

struct Stamped {
  Timestamp stamp;
  size_t message = 0;
};

// Sorts by header stamp (recorders may interleave) and drops repeated stamps, keeping the first.
std::vector<Stamped> SortedUnique(std::vector<Stamped> v, const std::string& bag,
                                  const std::string& topic) {
  std::stable_sort(v.begin(), v.end(),
                   [](const Stamped& a, const Stamped& b) { return a.stamp < b.stamp; });
  const size_t before = v.size();
  v.erase(std::unique(v.begin(), v.end(),
                      [](const Stamped& a, const Stamped& b) { return a.stamp == b.stamp; }),
          v.end());
  if (v.size() != before) {
    spdlog::warn("{}: {} messages on {} repeat an earlier header stamp; the first of each is used",
                 bag, before - v.size(), topic);
  }
  return v;
}

bool IsImageType(const std::string& type) {
  return type == "sensor_msgs/Image" || type == "sensor_msgs/CompressedImage";
}

std::string ImageTopics(const RosbagFile& bag) {
  std::string s;
  for (const RosbagConnection& c : bag.connections()) {
    if (!IsImageType(c.type)) continue;
    if (s.find(c.topic + " ") != std::string::npos) continue;
    s += (s.empty() ? "" : ", ") + c.topic + " (" + c.type + ")";
  }
  return s.empty() ? "none" : s;
}

// Checks that `topic` exists and carries `type` (for "image": sensor_msgs/Image or
// CompressedImage); returns false for an optional topic that is absent.
bool CheckTopic(const RosbagFile& bag, const std::string& topic, const std::string& type,
                const std::string& role, bool required) {
  const std::vector<uint32_t> ids = bag.ConnectionsOn(topic);
  if (ids.empty()) {
    if (!required) return false;
    throw InputError(bag.path(), 0,
                     "no topic " + topic + " (the " + role + " topic; image topics in the bag: " +
                         ImageTopics(bag) + "); name it with the option for the " + role +
                         " topic");
  }
  for (uint32_t id : ids) {
    const RosbagConnection* c = bag.connection(id);
    const bool ok = type == "image" ? IsImageType(c->type) : c->type == type;
    if (!ok) {
      throw InputError(bag.path(), 0,
                       "topic " + topic + " (the " + role + " topic) carries " + c->type +
                           ", expected " +
                           (type == "image" ? "sensor_msgs/Image or CompressedImage" : type));
    }
  }
  return true;
}

// cv::imdecode, its exceptions (e.g. an image over OPENCV_IO_MAX_IMAGE_PIXELS) as runtime_error.
cv::Mat Decode(const cv::Mat& buffer, const std::string& where) {
  try {
    return cv::imdecode(buffer, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    throw std::runtime_error(where + "compressed image does not decode: " + e.what());
  }
}

std::string Where(const std::string& topic, Timestamp stamp) {
  return "topic " + topic + ", message stamped " + stamp.ToString() + ": ";
}

// A view of the image rows (step may exceed the packed row size).
cv::Mat View(const RosImage& im, int type) {
  return cv::Mat(static_cast<int>(im.height), static_cast<int>(im.width), type,
                 const_cast<uint8_t*>(im.data), im.step);
}

void CheckLayout(const RosImage& im, int bytes_per_pixel, const std::string& where) {
  if (im.width == 0 || im.height == 0 || im.width > 16384 || im.height > 16384) {
    throw std::runtime_error(where + "image of " + std::to_string(im.width) + "x" +
                             std::to_string(im.height) + " pixels");
  }
  if (im.step < static_cast<uint64_t>(im.width) * bytes_per_pixel) {
    throw std::runtime_error(where + "row step " + std::to_string(im.step) + " is shorter than " +
                             std::to_string(im.width) + " pixels of " +
                             std::to_string(bytes_per_pixel) + " bytes (" + im.encoding + ")");
  }
}

}  // namespace

bool RosbagOptions::Check(std::string* error) const {
  std::string e;
  if (rgb_topic.empty()) e += "rgb_topic must not be empty; ";
  if (depth_topic.empty()) e += "depth_topic must not be empty; ";
  if (!(max_difference_s > 0)) e += "max_difference_s must be positive; ";
  if (!std::isfinite(offset_s)) e += "offset_s must be finite; ";
  if (error != nullptr) *error = e;
  return e.empty();
}

RosbagSource RosbagSource::Open(const std::string& path, const RosbagOptions& options) {
  std::string error;
  if (!options.Check(&error)) throw InputError(path, 0, "invalid bag options: " + error);
  RosbagSource source;
  source.path_ = path;
  source.options_ = options;

  std::vector<Stamped> rgb, depth;
  std::string parse_error;
  size_t index = 0;
  const RosbagFile::MessageVisitor visit = [&](const RosbagMessage& m, const RosbagConnection& c,
                                               const uint8_t* data) {
    const size_t i = index++;
    if (!parse_error.empty()) return;
    try {
      if (c.topic == options.rgb_topic && IsImageType(c.type)) {
        rgb.push_back({ParseRosHeaderStamp(data, m.size), i});
      } else if (c.topic == options.depth_topic && IsImageType(c.type)) {
        depth.push_back({ParseRosHeaderStamp(data, m.size), i});
      } else if (c.topic == options.camera_info_topic && c.type == "sensor_msgs/CameraInfo" &&
                 !source.camera_info_) {
        source.camera_info_ = ParseRosCameraInfo(data, m.size);
      }
    } catch (const std::exception& e) {
      parse_error = "topic " + c.topic + ", message " + std::to_string(i) + " (received " +
                    m.record_time.ToString() + "): " + e.what();
    }
  };
  source.bag_ = std::make_shared<const RosbagFile>(RosbagFile::Open(path, visit));
  const RosbagFile& bag = *source.bag_;
  if (!parse_error.empty()) throw InputError(path, 0, parse_error);
  CheckTopic(bag, options.rgb_topic, "image", "colour", true);
  CheckTopic(bag, options.depth_topic, "image", "depth", true);
  if (!options.camera_info_topic.empty() &&
      !CheckTopic(bag, options.camera_info_topic, "sensor_msgs/CameraInfo", "camera-info",
                  false)) {
    spdlog::info("{}: no camera-info topic {}", path, options.camera_info_topic);
  }
  source.rgb_count_ = rgb.size();
  source.depth_count_ = depth.size();
  if (rgb.empty()) throw InputError(path, 0, "no message on the colour topic " + options.rgb_topic);
  if (depth.empty()) {
    throw InputError(path, 0, "no message on the depth topic " + options.depth_topic);
  }
  rgb = SortedUnique(std::move(rgb), path, options.rgb_topic);
  depth = SortedUnique(std::move(depth), path, options.depth_topic);

  std::vector<Timestamp> rgb_stamps, depth_stamps;
  for (const Stamped& s : rgb) rgb_stamps.push_back(s.stamp);
  for (const Stamped& s : depth) depth_stamps.push_back(s.stamp);
  AssociationOptions assoc;
  assoc.max_difference_s = options.max_difference_s;
  assoc.offset_s = options.offset_s;
  for (const auto& [i, j] : AssociateTimestamps(rgb_stamps, depth_stamps, assoc)) {
    source.frames_.push_back({rgb[i].message, depth[j].message, rgb[i].stamp, depth[j].stamp});
  }
  if (source.frames_.empty()) {
    std::ostringstream os;
    os << "no colour image (" << rgb.size() << " on " << options.rgb_topic
       << ") has a depth image (" << depth.size() << " on " << options.depth_topic << ") within "
       << options.max_difference_s << " s (offset " << options.offset_s << " s)";
    throw InputError(path, 0, os.str());
  }
  spdlog::info("{}: associated {} of {} colour and {} depth images (window {} s)", path,
               source.frames_.size(), rgb.size(), depth.size(), options.max_difference_s);
  return source;
}

bool RosbagSource::has_tf() const {
  return std::any_of(bag_->connections().begin(), bag_->connections().end(),
                     [](const RosbagConnection& c) {
                       return c.type == "tf2_msgs/TFMessage" || c.type == "tf/tfMessage";
                     });
}

bool RosbagSource::Compressed(const RosbagMessage& m) const {
  const RosbagConnection* c = bag_->connection(m.connection);
  return c != nullptr && c->type == "sensor_msgs/CompressedImage";
}

Timestamp RosbagSource::stamp(size_t i) const {
  DETSLAM_CHECK_MSG(i < frames_.size(), "frame " << i << " of " << frames_.size());
  return frames_[i].rgb_stamp;
}

Timestamp RosbagSource::depth_stamp(size_t i) const {
  DETSLAM_CHECK_MSG(i < frames_.size(), "frame " << i << " of " << frames_.size());
  return frames_[i].depth_stamp;
}

RgbdImages RosbagSource::Load(size_t i, const PinholeCamera& camera) const {
  DETSLAM_CHECK_MSG(i < frames_.size(), "frame " << i << " of " << frames_.size());
  const Pair& f = frames_[i];
  RgbdImages out;
  const std::string rgb_where = Where(options_.rgb_topic, f.rgb_stamp);
  const std::string depth_where = Where(options_.depth_topic, f.depth_stamp);
  try {
    const RosbagMessage& rgb = bag_->messages()[f.rgb];
    const std::vector<uint8_t> rgb_bytes = bag_->Read(rgb);
    out.bgr = Compressed(rgb)
                  ? RosCompressedToBgr(ParseRosCompressedImage(rgb_bytes.data(), rgb_bytes.size()), rgb_where)
                  : RosImageToBgr(ParseRosImage(rgb_bytes.data(), rgb_bytes.size()), rgb_where);
    const RosbagMessage& depth = bag_->messages()[f.depth];
    const std::vector<uint8_t> depth_bytes = bag_->Read(depth);
    out.depth_m =
        Compressed(depth)
            ? RosCompressedToDepthMetres(ParseRosCompressedImage(depth_bytes.data(), depth_bytes.size()),
                                         depth_where)
            : RosImageToDepthMetres(ParseRosImage(depth_bytes.data(), depth_bytes.size()), depth_where);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(path_, 0, e.what());
  }
  if (out.bgr.cols != camera.width || out.bgr.rows != camera.height) {
    throw InputError(path_, 0,
                     rgb_where + "colour image is " + ImageSizeText(out.bgr.cols, out.bgr.rows) +
                         " but the camera settings say " + ImageSizeText(camera.width, camera.height));
  }
  if (out.depth_m.size() != out.bgr.size()) {
    throw InputError(path_, 0,
                     depth_where + "depth image is " + ImageSizeText(out.depth_m.cols, out.depth_m.rows) +
                         " but its colour image is " + ImageSizeText(out.bgr.cols, out.bgr.rows));
  }
  cv::cvtColor(out.bgr, out.gray, cv::COLOR_BGR2GRAY);
  return out;
}

cv::Mat RosImageToBgr(const RosImage& im, const std::string& where) {
  cv::Mat bgr;
  const std::string& e = im.encoding;
  if (e == "rgb8" || e == "bgr8") {
    CheckLayout(im, 3, where);
    if (e == "rgb8") {
      cv::cvtColor(View(im, CV_8UC3), bgr, cv::COLOR_RGB2BGR);
    } else {
      bgr = View(im, CV_8UC3).clone();
    }
  } else if (e == "rgba8" || e == "bgra8") {
    CheckLayout(im, 4, where);
    cv::cvtColor(View(im, CV_8UC4), bgr, e == "rgba8" ? cv::COLOR_RGBA2BGR : cv::COLOR_BGRA2BGR);
  } else if (e == "mono8" || e == "8UC1") {
    CheckLayout(im, 1, where);
    cv::cvtColor(View(im, CV_8UC1), bgr, cv::COLOR_GRAY2BGR);
  } else {
    throw std::runtime_error(where + "colour encoding '" + e +
                             "' is not supported (rgb8, bgr8, rgba8, bgra8, mono8)");
  }
  return bgr;
}

cv::Mat RosImageToDepthMetres(const RosImage& im, const std::string& where) {
  cv::Mat metres;
  const bool swap = im.big_endian;
  if (im.encoding == "32FC1") {
    CheckLayout(im, 4, where);
    metres.create(static_cast<int>(im.height), static_cast<int>(im.width), CV_32FC1);
    for (uint32_t y = 0; y < im.height; ++y) {
      const uint8_t* row = im.data + static_cast<size_t>(y) * im.step;
      float* out = metres.ptr<float>(static_cast<int>(y));
      for (uint32_t x = 0; x < im.width; ++x) {
        uint8_t b[4];
        std::memcpy(b, row + 4 * x, 4);
        if (swap) std::reverse(b, b + 4);
        float v;
        std::memcpy(&v, b, 4);
        out[x] = std::isfinite(v) && v > 0 ? v : 0.0f;
      }
    }
  } else if (im.encoding == "16UC1" || im.encoding == "mono16") {
    CheckLayout(im, 2, where);
    metres.create(static_cast<int>(im.height), static_cast<int>(im.width), CV_32FC1);
    for (uint32_t y = 0; y < im.height; ++y) {
      const uint8_t* row = im.data + static_cast<size_t>(y) * im.step;
      float* out = metres.ptr<float>(static_cast<int>(y));
      for (uint32_t x = 0; x < im.width; ++x) {
        const uint16_t v = swap ? static_cast<uint16_t>(row[2 * x] << 8 | row[2 * x + 1])
                                : static_cast<uint16_t>(row[2 * x + 1] << 8 | row[2 * x]);
        out[x] = static_cast<float>(v) * 0.001f;
      }
    }
  } else {
    throw std::runtime_error(where + "depth encoding '" + im.encoding +
                             "' is not supported (32FC1 metres, 16UC1 millimetres)");
  }
  return metres;
}

cv::Mat RosCompressedToBgr(const RosCompressedImage& im, const std::string& where) {
  if (im.data_size == 0) throw std::runtime_error(where + "empty compressed image");
  const cv::Mat buffer(1, static_cast<int>(im.data_size), CV_8UC1, const_cast<uint8_t*>(im.data));
  const cv::Mat decoded = Decode(buffer, where);
  if (decoded.empty() || decoded.depth() != CV_8U) {
    throw std::runtime_error(where + "compressed colour image (format '" + im.format +
                             "') does not decode to an 8-bit image");
  }
  cv::Mat bgr = DecodedToBgr(decoded);  // imdecode gives BGR for JPEG and PNG
  if (bgr.empty()) {
    throw std::runtime_error(where + "compressed colour image with " +
                             std::to_string(decoded.channels()) + " channels");
  }
  return bgr;
}

cv::Mat RosCompressedToDepthMetres(const RosCompressedImage& im, const std::string& where) {
  const std::string& f = im.format;
  if (f.find("compressedDepth") == std::string::npos) {
    throw std::runtime_error(where + "compressed depth format '" + f +
                             "' is not read (only image_transport's compressedDepth)");
  }
  constexpr size_t kHeader = 12;  // int32 format, float depthQuantA, float depthQuantB
  if (im.data_size <= kHeader) throw std::runtime_error(where + "compressedDepth data too short");
  float quant[2];
  std::memcpy(quant, im.data + 4, 8);
  const cv::Mat buffer(1, static_cast<int>(im.data_size - kHeader), CV_8UC1,
                       const_cast<uint8_t*>(im.data + kHeader));
  const cv::Mat raw = Decode(buffer, where);
  if (raw.empty() || raw.type() != CV_16UC1) {
    throw std::runtime_error(where + "compressedDepth data does not decode to a 16-bit PNG");
  }
  cv::Mat metres(raw.size(), CV_32FC1);
  const bool inverse = f.rfind("32FC1", 0) == 0;
  if (!inverse && f.rfind("16UC1", 0) != 0) {
    throw std::runtime_error(where + "compressedDepth of '" + f + "' (16UC1 or 32FC1 only)");
  }
  for (int y = 0; y < raw.rows; ++y) {
    const uint16_t* in = raw.ptr<uint16_t>(y);
    float* out = metres.ptr<float>(y);
    for (int x = 0; x < raw.cols; ++x) {
      float v = 0;
      if (in[x] != 0) v = inverse ? quant[0] / (static_cast<float>(in[x]) - quant[1]) : in[x] * 0.001f;
      out[x] = std::isfinite(v) && v > 0 ? v : 0.0f;
    }
  }
  return metres;
}

Settings SettingsFromCameraInfo(const RosCameraInfo& info, const std::string& source) {
  Settings s = PresetByName("fr3");
  s.source = "camera info in " + source;
  s.camera.width = static_cast<int>(info.width);
  s.camera.height = static_cast<int>(info.height);
  s.camera.fx = info.k[0];
  s.camera.cx = info.k[2];
  s.camera.fy = info.k[4];
  s.camera.cy = info.k[5];
  const std::vector<double>& d = info.d;
  if (info.distortion_model == "plumb_bob" && d.size() == 5) {
    s.camera.k1 = d[0];
    s.camera.k2 = d[1];
    s.camera.p1 = d[2];
    s.camera.p2 = d[3];
    s.camera.k3 = d[4];
  } else if (std::any_of(d.begin(), d.end(), [](double v) { return v != 0; })) {
    throw InputError(source, 0,
                     "camera info has distortion model '" + info.distortion_model + "' with " +
                         std::to_string(d.size()) +
                         " coefficients (only plumb_bob with 5 is read); pass --config FILE");
  }
  std::string error;
  if (!s.camera.Check(&error)) {
    throw InputError(source, 0, "camera info gives an invalid camera: " + error);
  }
  spdlog::info("{}: camera from its camera info: {}x{}, fx {} fy {} cx {} cy {}", source,
               s.camera.width, s.camera.height, s.camera.fx, s.camera.fy, s.camera.cx,
               s.camera.cy);
  return s;
}

Settings SettingsForBag(const std::string& bag_path, const std::optional<RosCameraInfo>& info) {
  try {
    return PresetForDataset(bag_path);
  } catch (const InputError&) {
    if (!info) {
      throw InputError(bag_path, 0,
                       "no camera preset matches the bag's file name and the bag has no camera "
                       "info; pass the settings with --config FILE");
    }
  }
  return SettingsFromCameraInfo(*info, bag_path);
}

}  // namespace detslam
