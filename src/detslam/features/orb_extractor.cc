#include "detslam/features/orb_extractor.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "detslam/core/check.h"
#include "detslam/core/math.h"
#include "detslam/features/keypoint_distribution.h"
#include "detslam/features/orb_pattern.h"

namespace detslam {
namespace {

constexpr int kPatchSize = 31;
constexpr int kHalfPatch = 15;
constexpr int kEdgeThreshold = 19;                 // border added around each level image
constexpr int kDetectBorder = kEdgeThreshold - 3;  // keypoints lie at least this far inside
constexpr int kCellSize = 35;                      // FAST threshold cells (ORB-SLAM's W)
constexpr int kFastRadius = 3;                     // FAST needs this many pixels around a candidate

// Half-widths of the radius-15 circular patch, per row offset 0..15: u^2 + v^2 <= 15^2.
std::array<int, kHalfPatch + 1> CircleHalfWidths() {
  std::array<int, kHalfPatch + 1> u_max{};
  for (int v = 0; v <= kHalfPatch; ++v) {
    u_max[v] = static_cast<int>(std::floor(std::sqrt(double(kHalfPatch * kHalfPatch - v * v))));
  }
  return u_max;
}

// Intensity-centroid orientation in degrees [0, 360) of the patch centred at `center`.
float CentroidAngle(const cv::Mat& image, cv::Point center,
                    const std::array<int, kHalfPatch + 1>& u_max) {
  const int step = static_cast<int>(image.step1());
  const uint8_t* c = image.ptr<uint8_t>(center.y) + center.x;
  long m10 = 0, m01 = 0;
  for (int u = -kHalfPatch; u <= kHalfPatch; ++u) m10 += u * c[u];
  for (int v = 1; v <= kHalfPatch; ++v) {
    long row_sum_diff = 0;  // sum over u of (I(u, v) - I(u, -v)), multiplied by v below
    const int d = u_max[v];
    for (int u = -d; u <= d; ++u) {
      const int below = c[u + v * step];
      const int above = c[u - v * step];
      row_sum_diff += below - above;
      m10 += u * (below + above);
    }
    m01 += v * row_sum_diff;
  }
  double angle = std::atan2(static_cast<double>(m01), static_cast<double>(m10)) * 180.0 / kPi;
  if (angle < 0) angle += 360.0;
  if (angle >= 360.0) angle -= 360.0;
  return static_cast<float>(angle);
}

// The pattern's 512 sample points as floats: x of pair k's first point at [2k], second at [2k+1].
struct PatternPoints {
  std::array<float, 512> x, y;
};

PatternPoints MakePatternPoints() {
  PatternPoints points;
  const std::array<BriefPair, 256>& pattern = OrbPattern();
  for (int k = 0; k < 256; ++k) {
    points.x[2 * k] = pattern[k].x1;
    points.y[2 * k] = pattern[k].y1;
    points.x[2 * k + 1] = pattern[k].x2;
    points.y[2 * k + 1] = pattern[k].y2;
  }
  return points;
}

// 256-bit steered BRIEF on the blurred image at `center` with orientation `angle_deg`: the pattern
// is rotated by the angle (rounded to whole pixels, half away from zero) and bit k of the
// descriptor (byte k / 8, bit k % 8) is I(first point) < I(second point).
void ComputeDescriptor(const cv::Mat& blurred, cv::Point center, float angle_deg, uint8_t* out) {
  static const PatternPoints points = MakePatternPoints();
  const double a = angle_deg * kPi / 180.0;
  const float ca = static_cast<float>(std::cos(a));
  const float sa = static_cast<float>(std::sin(a));
  const int step = static_cast<int>(blurred.step1());
  const auto round = [](float v) { return static_cast<int>(v + (v >= 0.f ? 0.5f : -0.5f)); };
  std::array<int, 512> offsets;  // a plain loop the compiler can vectorise
  for (int k = 0; k < 512; ++k) {
    const float px = points.x[k], py = points.y[k];
    offsets[k] = round(px * sa + py * ca) * step + round(px * ca - py * sa);
  }
  const uint8_t* c = blurred.ptr<uint8_t>(center.y) + center.x;
  for (int byte = 0; byte < 32; ++byte) {
    unsigned value = 0;
    for (int bit = 0; bit < 8; ++bit) {
      const int k = 2 * (byte * 8 + bit);
      value |= static_cast<unsigned>(c[offsets[k]] < c[offsets[k + 1]]) << bit;
    }
    out[byte] = static_cast<uint8_t>(value);
  }
}

// The level-0 pixel a level coordinate maps to (v = level coordinate * scale, rounded to float as
// the keypoint test always did), clamped to `size`.
int LevelZeroPixel(float v, int size) {
  return std::clamp(static_cast<int>(std::lround(v)), 0, size - 1);
}

bool Masked(const cv::Mat& mask, float x, float y) {
  return mask.at<uint8_t>(LevelZeroPixel(y, mask.rows), LevelZeroPixel(x, mask.cols)) != 0;
}

// Whether every corner FAST could report at integer level positions [x_begin, x_end) x [y_begin,
// y_end) would be dropped by Masked: the level-0 pixels they map to (a monotone map) are all set.
bool CellFullyMasked(const cv::Mat& mask, double scale, int x_begin, int x_end, int y_begin,
                     int y_end) {
  const auto pixel = [scale](int v, int size) {
    return LevelZeroPixel(static_cast<float>(v * scale), size);
  };
  const int x0 = pixel(x_begin, mask.cols), x1 = pixel(x_end - 1, mask.cols);
  const int y0 = pixel(y_begin, mask.rows), y1 = pixel(y_end - 1, mask.rows);
  const cv::Rect area(x0, y0, x1 - x0 + 1, y1 - y0 + 1);
  return cv::countNonZero(mask(area)) == area.area();
}

// FAST corners (with non-max suppression) of one level inside [kDetectBorder, size -
// kDetectBorder), by cells of about kCellSize pixels: the whole area at ini_th_fast first
// (DetectStrongCorners, no mask needed), then, in DetectCorners, in each cell that has no
// (unmasked) corner, that cell again at min_th_fast (not if the mask covers the whole cell:
// nothing found there could be kept). Corners whose level-0 position is masked are dropped before
// the per-cell decision. Positions are level pixel coordinates.
std::vector<cv::KeyPoint> DetectStrongCorners(const cv::Mat& level_image, const OrbOptions& options) {
  constexpr int kMargin = kDetectBorder - kFastRadius;
  std::vector<cv::KeyPoint> found;
  cv::FAST(level_image(cv::Rect(kMargin, kMargin, level_image.cols - 2 * kMargin,
                                level_image.rows - 2 * kMargin)),
           found, options.ini_th_fast, true);
  for (cv::KeyPoint& kp : found) {
    kp.pt.x += kMargin;
    kp.pt.y += kMargin;
  }
  return found;
}

// The level's corners outside the mask from its strong corners (see above).
void DetectCorners(const cv::Mat& level_image, double scale, const cv::Mat& ignore_mask,
                   const OrbOptions& options, const std::vector<cv::KeyPoint>& strong,
                   std::vector<cv::KeyPoint>* corners) {
  corners->clear();
  const int region_w = level_image.cols - 2 * kDetectBorder;
  const int region_h = level_image.rows - 2 * kDetectBorder;
  const int cols = std::max(1, region_w / kCellSize);
  const int rows = std::max(1, region_h / kCellSize);
  const double cell_w = static_cast<double>(region_w) / cols;
  const double cell_h = static_cast<double>(region_h) / rows;
  const auto keep = [&](const cv::KeyPoint& kp) {
    return ignore_mask.empty() || !Masked(ignore_mask, kp.pt.x * scale, kp.pt.y * scale);
  };

  std::vector<char> cell_has_corner(cols * rows, 0);
  for (const cv::KeyPoint& kp : strong) {
    if (!keep(kp)) continue;
    const int cx = std::clamp(static_cast<int>((kp.pt.x - kDetectBorder) / cell_w), 0, cols - 1);
    const int cy = std::clamp(static_cast<int>((kp.pt.y - kDetectBorder) / cell_h), 0, rows - 1);
    cell_has_corner[cy * cols + cx] = 1;
    corners->push_back(kp);
  }

  // Cells without any: retry at the low threshold, on the cell grown by the FAST radius.
  std::vector<cv::KeyPoint> found;
  for (int cy = 0; cy < rows; ++cy) {
    for (int cx = 0; cx < cols; ++cx) {
      if (cell_has_corner[cy * cols + cx]) continue;
      const int x_begin = kDetectBorder + static_cast<int>(std::lround(cx * cell_w));
      const int x_end = kDetectBorder + static_cast<int>(std::lround((cx + 1) * cell_w));
      const int y_begin = kDetectBorder + static_cast<int>(std::lround(cy * cell_h));
      const int y_end = kDetectBorder + static_cast<int>(std::lround((cy + 1) * cell_h));
      // A cell under the mask would only yield corners that are dropped: skip its FAST run.
      if (options.skip_masked_cells && !ignore_mask.empty() &&
          CellFullyMasked(ignore_mask, scale, x_begin, x_end, y_begin, y_end)) {
        continue;
      }
      const cv::Rect roi(x_begin - kFastRadius, y_begin - kFastRadius,
                         x_end - x_begin + 2 * kFastRadius, y_end - y_begin + 2 * kFastRadius);
      found.clear();
      cv::FAST(level_image(roi), found, options.min_th_fast, true);
      for (cv::KeyPoint& kp : found) {
        kp.pt.x += roi.x;
        kp.pt.y += roi.y;
        if (kp.pt.x < x_begin || kp.pt.x >= x_end || kp.pt.y < y_begin || kp.pt.y >= y_end) {
          continue;
        }
        if (keep(kp)) corners->push_back(kp);
      }
    }
  }
}

}  // namespace

bool OrbOptions::Check(std::string* error) const {
  std::ostringstream os;
  if (num_features < 1) os << "num_features must be >= 1 (got " << num_features << "); ";
  if (!(scale_factor > 1.0) || !(scale_factor < 10.0)) {
    os << "scale_factor must be in (1, 10) (got " << scale_factor << "); ";
  }
  if (num_levels < 1 || num_levels > 32) {
    os << "num_levels must be in [1, 32] (got " << num_levels << "); ";
  }
  if (min_th_fast < 1 || min_th_fast > 254) {
    os << "min_th_fast must be in [1, 254] (got " << min_th_fast << "); ";
  }
  if (ini_th_fast < min_th_fast || ini_th_fast > 254) {
    os << "ini_th_fast must be in [min_th_fast, 254] (got " << ini_th_fast << "); ";
  }
  const std::string message = os.str();
  if (error != nullptr) *error = message;
  return message.empty();
}

OrbExtractor::OrbExtractor(const OrbOptions& options) : options_(options) {
  std::string error;
  if (!options_.Check(&error)) throw InputError("OrbOptions: " + error);
  const int levels = options_.num_levels;
  scale_factors_.resize(levels);
  inv_scale_factors_.resize(levels);
  level_sigma2_.resize(levels);
  inv_level_sigma2_.resize(levels);
  for (int l = 0; l < levels; ++l) {
    scale_factors_[l] = l == 0 ? 1.0 : scale_factors_[l - 1] * options_.scale_factor;
    inv_scale_factors_[l] = 1.0 / scale_factors_[l];
    level_sigma2_[l] = scale_factors_[l] * scale_factors_[l];
    inv_level_sigma2_[l] = 1.0 / level_sigma2_[l];
  }
  // Geometric series n_l = n_0 f^l with f = 1 / scale_factor, the remainder to the top level.
  features_per_level_.resize(levels);
  const double f = 1.0 / options_.scale_factor;
  double desired = options_.num_features * (1.0 - f) / (1.0 - std::pow(f, levels));
  int assigned = 0;
  for (int l = 0; l + 1 < levels; ++l) {
    features_per_level_[l] = static_cast<int>(std::lround(desired));
    assigned += features_per_level_[l];
    desired *= f;
  }
  features_per_level_[levels - 1] = std::max(0, options_.num_features - assigned);
}

OrbPyramid OrbExtractor::Prepare(const cv::Mat& gray) const {
  if (gray.empty() || gray.type() != CV_8UC1) {
    throw InputError("OrbExtractor::Extract: image must be a non-empty CV_8UC1 image");
  }
  OrbPyramid pyramid;
  pyramid.size = gray.size();
  for (int level = 0; level < options_.num_levels; ++level) {
    const cv::Size size(static_cast<int>(std::lround(gray.cols * inv_scale_factors_[level])),
                        static_cast<int>(std::lround(gray.rows * inv_scale_factors_[level])));
    if (size.width <= 2 * kDetectBorder + 1 || size.height <= 2 * kDetectBorder + 1) break;
    OrbPyramid::Level l;
    if (level == 0) {
      l.image = gray;
    } else {
      cv::resize(pyramid.levels.back().image, l.image, size, 0, 0, cv::INTER_LINEAR);
    }
    cv::copyMakeBorder(l.image, l.padded, kEdgeThreshold, kEdgeThreshold, kEdgeThreshold,
                       kEdgeThreshold, cv::BORDER_REFLECT_101);
    cv::GaussianBlur(l.padded, l.blurred, cv::Size(7, 7), 2, 2, cv::BORDER_REFLECT_101);
    l.strong = DetectStrongCorners(l.image, options_);
    pyramid.levels.push_back(std::move(l));
  }
  return pyramid;
}

void OrbExtractor::Extract(const cv::Mat& gray, const cv::Mat& ignore_mask,
                           std::vector<cv::KeyPoint>* keypoints, cv::Mat* descriptors) const {
  Extract(Prepare(gray), ignore_mask, keypoints, descriptors);
}

void OrbExtractor::Extract(const OrbPyramid& pyramid, const cv::Mat& ignore_mask,
                           std::vector<cv::KeyPoint>* keypoints, cv::Mat* descriptors) const {
  DETSLAM_CHECK(keypoints != nullptr && descriptors != nullptr);
  if (!ignore_mask.empty() &&
      (ignore_mask.type() != CV_8UC1 || ignore_mask.size() != pyramid.size)) {
    throw InputError("OrbExtractor::Extract: ignore_mask must be empty or CV_8UC1 of image size");
  }
  keypoints->clear();
  static const std::array<int, kHalfPatch + 1> u_max = CircleHalfWidths();

  std::vector<cv::KeyPoint> result;
  std::vector<std::array<uint8_t, 32>> desc_rows;
  result.reserve(options_.num_features + 16);
  desc_rows.reserve(options_.num_features + 16);

  std::vector<cv::KeyPoint> candidates;
  for (size_t level = 0; level < pyramid.levels.size(); ++level) {
    const OrbPyramid::Level& l = pyramid.levels[level];
    const double scale = scale_factors_[level];
    DetectCorners(l.image, scale, ignore_mask, options_, l.strong, &candidates);

    const std::vector<size_t> chosen = DistributeQuadtree(
        candidates, kDetectBorder, static_cast<float>(l.image.cols - kDetectBorder), kDetectBorder,
        static_cast<float>(l.image.rows - kDetectBorder), features_per_level_[level]);
    for (size_t i : chosen) {
      const cv::KeyPoint& c = candidates[i];
      const cv::Point center(static_cast<int>(std::lround(c.pt.x)) + kEdgeThreshold,
                             static_cast<int>(std::lround(c.pt.y)) + kEdgeThreshold);
      cv::KeyPoint kp;
      kp.angle = CentroidAngle(l.padded, center, u_max);
      kp.response = c.response;
      kp.octave = static_cast<int>(level);
      kp.size = static_cast<float>(kPatchSize * scale);
      kp.pt = cv::Point2f(static_cast<float>(c.pt.x * scale), static_cast<float>(c.pt.y * scale));
      desc_rows.emplace_back();
      ComputeDescriptor(l.blurred, center, kp.angle, desc_rows.back().data());
      result.push_back(kp);
    }
  }

  *keypoints = std::move(result);
  descriptors->create(static_cast<int>(desc_rows.size()), 32, CV_8UC1);
  for (size_t i = 0; i < desc_rows.size(); ++i) {
    std::memcpy(descriptors->ptr<uint8_t>(static_cast<int>(i)), desc_rows[i].data(), 32);
  }
}

// On x86-64 GCC/Clang build a POPCNT variant next to the portable one and pick at load time
// (the default build targets plain x86-64, where __builtin_popcountll is a library call).
// The popcnt clone is chosen by an ifunc resolver that runs while the program is being loaded;
// ThreadSanitizer instruments the resolver before its runtime is up (a crash at start), so its
// builds keep the default version only.
#if defined(__SANITIZE_THREAD__)
#define DETSLAM_TSAN 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define DETSLAM_TSAN 1
#endif
#endif
#if defined(__x86_64__) && defined(__GNUC__) && defined(__linux__) && !defined(DETSLAM_TSAN)
__attribute__((target_clones("popcnt", "default")))
#endif
int DescriptorDistance(const uint8_t* a, const uint8_t* b) {
  int distance = 0;
  for (int i = 0; i < 32; i += 8) {
    uint64_t wa, wb;
    std::memcpy(&wa, a + i, 8);
    std::memcpy(&wb, b + i, 8);
    distance += __builtin_popcountll(wa ^ wb);
  }
  return distance;
}

}  // namespace detslam
