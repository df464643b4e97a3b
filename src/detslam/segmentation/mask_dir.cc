#include "detslam/segmentation/mask_dir.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <filesystem>
#include <limits>
#include <numeric>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <sstream>

#include "detslam/core/atomic_file.h"
#include "detslam/core/check.h"
#include "detslam/io/text_lines.h"
#include "detslam/segmentation/coco_classes.h"

namespace detslam {
namespace fs = std::filesystem;

namespace {

int ParseIntField(const std::string& path, int line, const std::string& text, const char* what) {
  const double v = ParseDoubleField(path, line, text);
  if (v != std::floor(v) || std::abs(v) > 1e9) {
    throw InputError(path, line, std::string(what) + " must be an integer, got '" + text + "'");
  }
  return static_cast<int>(v);
}

std::string NameToField(std::string name) {
  std::replace(name.begin(), name.end(), ' ', '_');
  return name.empty() ? "unknown" : name;
}

std::string FieldToName(std::string field) {
  std::replace(field.begin(), field.end(), '_', ' ');
  return field;
}

}  // namespace

std::map<int64_t, std::vector<MaskRecord>> ReadInstanceList(const std::string& path) {
  std::map<int64_t, std::vector<MaskRecord>> out;
  std::map<int64_t, std::set<int>> ids;
  ForEachDataLine(path, [&](int line, const std::vector<std::string>& f) {
    if (f.size() != 8 && f.size() != 9) {
      throw InputError(path, line,
                       "expected 'timestamp id class_id class_name score x y w h' (9 fields) or "
                       "'timestamp id class_name score x y w h' (8), got " +
                           std::to_string(f.size()) + " fields");
    }
    MaskRecord r;
    if (!ParseTimestamp(f[0], &r.stamp)) {
      throw InputError(path, line, "malformed timestamp '" + f[0] + "'");
    }
    r.id = ParseIntField(path, line, f[1], "id");
    if (r.id < 1 || r.id > 65535) {
      throw InputError(path, line, "id must be in 1..65535, got " + f[1]);
    }
    size_t k = 2;
    if (f.size() == 9) {
      r.class_id = ParseIntField(path, line, f[k++], "class_id");
      if (r.class_id < -1) throw InputError(path, line, "class_id must be >= -1");
      r.class_name = FieldToName(f[k++]);
    } else {
      r.class_name = FieldToName(f[k++]);
      r.class_id = CocoClassId(r.class_name);
    }
    const double score = ParseDoubleField(path, line, f[k++]);
    if (score < 0 || score > 1)
      throw InputError(path, line, "score must be in [0, 1], got " + f[k - 1]);
    r.score = static_cast<float>(score);
    int v[4];
    for (int i = 0; i < 4; ++i) v[i] = ParseIntField(path, line, f[k++], "box coordinate");
    if (v[2] < 0 || v[3] < 0) throw InputError(path, line, "box width and height must be >= 0");
    r.box = cv::Rect(v[0], v[1], v[2], v[3]);
    if (!ids[r.stamp.ns].insert(r.id).second) {
      throw InputError(path, line, "duplicate id " + f[1] + " for frame " + f[0]);
    }
    out[r.stamp.ns].push_back(std::move(r));
  });
  return out;
}

std::string MaskPngPath(const std::string& dir, Timestamp stamp) {
  return (fs::path(dir) / (stamp.ToString() + ".png")).string();
}

std::string InstanceMaskPngPath(const std::string& dir, Timestamp stamp, int id) {
  return (fs::path(dir) / (stamp.ToString() + "_" + std::to_string(id) + ".png")).string();
}

MaskDirSegmenter::MaskDirSegmenter(const std::string& dir, const std::string& name)
    : dir_(dir), name_(name) {
  if (!fs::is_directory(dir)) throw InputError(dir, 0, "masks folder does not exist");
  const std::string list = (fs::path(dir) / "instances.txt").string();
  if (!fs::exists(list)) {
    throw InputError(list, 0, "missing instance list (see segmentation/mask_dir.h for the format)");
  }
  records_ = ReadInstanceList(list);
  spdlog::debug("{}: {} frames with instances listed in {}", name_, records_.size(), list);
}

std::vector<Instance> MaskDirSegmenter::Segment(const SegmenterInput& input) {
  std::vector<Instance> out;
  const auto it = records_.find(input.stamp.ns);
  const std::string png = MaskPngPath(dir_, input.stamp);
  const bool has_png = fs::exists(png);
  if (it == records_.end() && !has_png) return out;
  cv::Mat ids;
  if (has_png) {
    ids = cv::imread(png, cv::IMREAD_UNCHANGED);
    if (ids.empty()) throw InputError(png, 0, "cannot decode mask image");
    if (ids.channels() != 1 || (ids.depth() != CV_8U && ids.depth() != CV_16U)) {
      throw InputError(png, 0, "mask image must be 8- or 16-bit single channel");
    }
    if (!input.bgr.empty() && ids.size() != input.bgr.size()) {
      std::ostringstream os;
      os << "mask is " << ids.cols << "x" << ids.rows << " but the colour image is "
         << input.bgr.cols << "x" << input.bgr.rows;
      throw InputError(png, 0, os.str());
    }
    ids.convertTo(ids, CV_32S);
  }
  const cv::Size size = has_png ? ids.size() : input.bgr.size();
  const cv::Rect image(0, 0, size.width, size.height);
  std::set<int> listed;
  if (it != records_.end()) {
    for (const MaskRecord& r : it->second) {
      Instance in;
      in.class_id = r.class_id;
      in.class_name = r.class_name;
      in.score = r.score;
      in.box = size.area() > 0 ? (r.box & image) : r.box;
      const std::string own = InstanceMaskPngPath(dir_, input.stamp, r.id);
      if (fs::exists(own)) {
        cv::Mat m = cv::imread(own, cv::IMREAD_UNCHANGED);
        if (m.empty()) throw InputError(own, 0, "cannot decode instance mask image");
        if (m.type() != CV_8UC1) throw InputError(own, 0, "instance mask must be 8-bit single channel");
        if (size.area() > 0 && m.size() != size) {
          throw InputError(own, 0, "instance mask is " + std::to_string(m.cols) + "x" +
                                       std::to_string(m.rows) + ", not the image's size");
        }
        in.mask = (m > 0);
      } else if (has_png) {
        in.mask = (ids == r.id);
      }
      listed.insert(r.id);
      out.push_back(std::move(in));
    }
  }
  if (has_png) {
    double max_id = 0;
    cv::minMaxLoc(ids, nullptr, &max_id);
    if (max_id > 0) {
      std::vector<uint8_t> seen(static_cast<size_t>(max_id) + 1, 0);
      for (int y = 0; y < ids.rows; ++y) {
        const int* row = ids.ptr<int>(y);
        for (int x = 0; x < ids.cols; ++x) seen[row[x]] = 1;
      }
      for (size_t v = 1; v < seen.size(); ++v) {
        if (seen[v] && !listed.count(static_cast<int>(v))) {
          throw InputError(png, 0,
                           "holds instance id " + std::to_string(v) + " that " + dir_ +
                               "/instances.txt does not list for " + input.stamp.ToString());
        }
      }
    }
  }
  return out;
}

MaskDirWriter::MaskDirWriter(const std::string& dir, const std::string& header)
    : dir_(dir), header_(header) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) {
    throw InputError(dir, 0, "cannot create masks folder: " + ec.message());
  }
}

void MaskDirWriter::Add(Timestamp stamp, const cv::Size& size,
                        const std::vector<Instance>& instances) {
  ++frames_;
  if (instances.empty()) return;
  DETSLAM_CHECK_MSG(instances.size() <= 65535, "too many instances in one frame");
  std::vector<size_t> order(instances.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return instances[a].score < instances[b].score;  // higher scores painted last, they win
  });
  cv::Mat ids(size, CV_16UC1, cv::Scalar(0));
  const cv::Rect image(0, 0, size.width, size.height);
  for (size_t k : order) {
    const Instance& in = instances[k];
    const auto id = static_cast<uint16_t>(k + 1);
    if (in.mask.empty()) {
      ids(in.box & image).setTo(id);
    } else {
      DETSLAM_CHECK(in.mask.size() == size && in.mask.type() == CV_8UC1);
      ids.setTo(id, in.mask);
    }
  }
  auto write_png = [](const std::string& path, const cv::Mat& image) {
    std::vector<uint8_t> png;
    if (!cv::imencode(".png", image, png)) throw InputError(path, 0, "cannot encode mask PNG");
    WriteBytesAtomically(path, std::string(png.begin(), png.end()));
  };
  write_png(MaskPngPath(dir_, stamp), ids);
  // A mask the id image does not hold exactly (pixels another instance won) gets its own file.
  for (size_t k = 0; k < instances.size(); ++k) {
    cv::Mat own;
    if (instances[k].mask.empty()) {
      own = cv::Mat(size, CV_8UC1, cv::Scalar(0));
      own(instances[k].box & image).setTo(255);
    } else {
      own = instances[k].mask > 0;
    }
    const cv::Mat kept = ids == static_cast<int>(k + 1);
    if (cv::countNonZero(own != kept) > 0) {
      write_png(InstanceMaskPngPath(dir_, stamp, static_cast<int>(k + 1)), own);
    }
  }
  for (size_t k = 0; k < instances.size(); ++k) {
    const Instance& in = instances[k];
    std::ostringstream os;
    os.precision(std::numeric_limits<float>::max_digits10);  // scores read back bit-exact
    os << stamp.ToString() << " " << k + 1 << " " << in.class_id << " "
       << NameToField(in.class_name) << " " << in.score << " " << in.box.x << " " << in.box.y << " "
       << in.box.width << " " << in.box.height;
    lines_.push_back(os.str());
  }
}

void MaskDirWriter::Flush() {
  WriteFileAtomically((fs::path(dir_) / "instances.txt").string(), [&](std::ostream& os) {
    os << "# instance masks: <timestamp>.png beside this file (16-bit ids, 0 = none)\n";
    if (!header_.empty()) os << "# " << header_ << "\n";
    os << "# timestamp id class_id class_name score x y w h\n";
    for (const std::string& l : lines_) os << l << "\n";
  });
}

void WriteMasks(const std::string& dir, const std::vector<Timestamp>& stamps,
                const std::vector<std::vector<Instance>>& instances, const cv::Size& size) {
  DETSLAM_CHECK(stamps.size() == instances.size());
  MaskDirWriter writer(dir);
  for (size_t i = 0; i < stamps.size(); ++i) writer.Add(stamps[i], size, instances[i]);
  writer.Finish();
}

}  // namespace detslam
