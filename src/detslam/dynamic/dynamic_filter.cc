#include "detslam/dynamic/dynamic_filter.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "detslam/core/check.h"
#include "detslam/dynamic/ellipse_dilate.h"

namespace detslam {
namespace {

constexpr double kMaxDepthM = 1000.0;  // depths beyond this are treated as invalid
constexpr int64_t kMaxHistogramBins = 10'000'000;

bool ValidDepth(float d) { return d > 0.0f && std::isfinite(d) && d < kMaxDepthM; }

using InstanceRegion = DynamicRegions::Region;

void CheckOptions(const DynamicFilterOptions& options) {
  std::string error;
  DETSLAM_CHECK_MSG(options.Check(&error), "invalid DynamicFilterOptions: " << error);
}

void CheckMask(const cv::Mat& mask, const cv::Size& image_size) {
  if (mask.empty()) return;
  if (mask.type() != CV_8UC1 || mask.size() != image_size) {
    std::ostringstream os;
    os << "instance mask must be CV_8UC1 of the image size " << image_size.width << "x"
       << image_size.height << ", got type " << mask.type() << " size " << mask.cols << "x"
       << mask.rows;
    throw InputError(os.str());
  }
}

void CheckDepth(const cv::Mat& depth_m) {
  if (!depth_m.empty() && depth_m.type() != CV_32FC1) {
    throw InputError("depth image must be CV_32FC1 (metres), got type " +
                     std::to_string(depth_m.type()));
  }
}

// The image size the instances refer to: the depth image's, else the first mask's, else the
// smallest size that holds every box.
cv::Size InferImageSize(const std::vector<Instance>& instances, const cv::Mat& depth_m) {
  if (!depth_m.empty()) return depth_m.size();
  for (const Instance& instance : instances) {
    if (!instance.mask.empty()) return instance.mask.size();
  }
  cv::Size size(0, 0);
  for (const Instance& instance : instances) {
    size.width = std::max(size.width, instance.box.x + instance.box.width);
    size.height = std::max(size.height, instance.box.y + instance.box.height);
  }
  return size;
}

InstanceRegion BuildRegion(const Instance& instance, const cv::Mat& depth_m,
                           const cv::Size& image_size, const DynamicFilterOptions& options) {
  CheckMask(instance.mask, image_size);
  const cv::Rect image(0, 0, image_size.width, image_size.height);
  InstanceRegion region;
  region.box = instance.box & image;
  const bool box_only = instance.mask.empty();
  const cv::Rect source = box_only ? region.box : cv::boundingRect(instance.mask);
  if (source.empty()) return region;  // nothing to reject
  const int r = options.mask_dilation_px;
  region.roi =
      cv::Rect(source.x - r, source.y - r, source.width + 2 * r, source.height + 2 * r) & image;
  cv::Mat local = cv::Mat::zeros(region.roi.size(), CV_8UC1);
  if (box_only) {
    local(region.box - region.roi.tl()).setTo(255);
  } else {
    cv::compare(instance.mask(region.roi), 0, local, cv::CMP_GT);
  }
  region.dilated = r > 0 ? DilateEllipse(local, r) : local;
  if (options.depth_step && !depth_m.empty()) {
    region.interval = ObjectDepthInterval(depth_m, instance.mask, instance.box, options);
  }
  return region;
}

bool InsideDilated(const InstanceRegion& region, const cv::Point& p) {
  return region.roi.contains(p) && region.dilated.at<uint8_t>(p - region.roi.tl()) != 0;
}

}  // namespace

bool DynamicFilterOptions::Check(std::string* error) const {
  auto fail = [error](const std::string& message) {
    if (error != nullptr) *error = message;
    return false;
  };
  if (!(min_score >= 0.0f && min_score <= 1.0f)) return fail("min_score must lie in [0, 1]");
  if (mask_dilation_px < 0 || mask_dilation_px > 200) {
    return fail("mask_dilation_px must lie in [0, 200]");
  }
  if (!(alpha >= 0.0 && alpha <= 10.0)) return fail("alpha must lie in [0, 10]");
  if (!(depth_bin_m >= 1e-3 && depth_bin_m <= 10.0)) {
    return fail("depth_bin_m must lie in [0.001, 10]");
  }
  if (!(mode_window_m >= 0.5 * depth_bin_m && mode_window_m <= kMaxDepthM)) {
    return fail("mode_window_m must be at least depth_bin_m / 2");
  }
  if (!(mode_min_bin_fraction >= 0.0 && mode_min_bin_fraction <= 1.0)) {
    return fail("mode_min_bin_fraction must lie in [0, 1]");
  }
  for (const std::string& name : dynamic_classes) {
    if (name.empty()) return fail("dynamic_classes must not contain an empty name");
  }
  return true;
}

bool DynamicFilterOptions::Uses(const Instance& instance) const {
  return instance.score >= min_score && IsDynamicClass(instance.class_name);
}

bool DynamicFilterOptions::IsDynamicClass(const std::string& class_name) const {
  return std::find(dynamic_classes.begin(), dynamic_classes.end(), class_name) !=
         dynamic_classes.end();
}

DepthRange DominantDepthMode(const std::vector<float>& depths, double bin_m, double window_m,
                             double min_bin_fraction) {
  DETSLAM_CHECK_MSG(bin_m > 0.0 && window_m >= 0.5 * bin_m,
                    "bin_m " << bin_m << " window_m " << window_m);
  DepthRange out;
  float lowest = std::numeric_limits<float>::infinity();
  float highest = -lowest;
  for (float d : depths) {
    if (!ValidDepth(d)) continue;
    lowest = std::min(lowest, d);
    highest = std::max(highest, d);
  }
  if (!(lowest <= highest)) return out;
  // Valid depths are positive and below kMaxDepthM, so the bin, floor(d / bin_m), is the
  // quotient truncated; each depth's bin is computed once and kept for the last pass.
  auto bin_of = [bin_m](float d) { return static_cast<int64_t>(static_cast<double>(d) / bin_m); };
  const int64_t first_bin = bin_of(lowest);
  const int64_t num_bins = bin_of(highest) - first_bin + 1;
  DETSLAM_CHECK_MSG(num_bins <= kMaxHistogramBins, "depth histogram too large: " << num_bins);
  std::vector<int> histogram(static_cast<size_t>(num_bins), 0);
  std::vector<std::pair<float, int64_t>> binned;  // valid depths with their bin
  binned.reserve(depths.size());
  for (float d : depths) {
    if (!ValidDepth(d)) continue;
    const int64_t bin = bin_of(d) - first_bin;
    ++histogram[static_cast<size_t>(bin)];
    binned.emplace_back(d, bin);
  }
  // The most populated bin; ties go to the nearer bin (max_element returns the first maximum).
  const int64_t mode = std::max_element(histogram.begin(), histogram.end()) - histogram.begin();
  const int mode_count = histogram[static_cast<size_t>(mode)];
  const int populated =
      std::max(1, static_cast<int>(std::ceil(min_bin_fraction * static_cast<double>(mode_count))));
  int64_t run_lo = mode;
  int64_t run_hi = mode;
  while (run_lo > 0 && histogram[static_cast<size_t>(run_lo - 1)] >= populated) --run_lo;
  while (run_hi + 1 < num_bins && histogram[static_cast<size_t>(run_hi + 1)] >= populated) ++run_hi;
  const double centre = (static_cast<double>(first_bin + mode) + 0.5) * bin_m;
  float kept_min = std::numeric_limits<float>::infinity();
  float kept_max = -kept_min;
  for (const auto& [d, bin] : binned) {
    if (bin < run_lo || bin > run_hi || std::abs(d - centre) > window_m) continue;
    kept_min = std::min(kept_min, d);
    kept_max = std::max(kept_max, d);
  }
  if (kept_min <= kept_max) {
    out.valid = true;
    out.min = kept_min;
    out.max = kept_max;
  }
  return out;
}

DepthInterval ObjectDepthInterval(const cv::Mat& depth_m, const cv::Mat& mask, const cv::Rect& box,
                                  const DynamicFilterOptions& options) {
  DepthInterval out;
  if (depth_m.empty()) return out;
  CheckDepth(depth_m);
  CheckMask(mask, depth_m.size());
  const cv::Rect clipped = box & cv::Rect(0, 0, depth_m.cols, depth_m.rows);
  if (clipped.empty()) return out;
  std::vector<float> object(static_cast<size_t>(clipped.area()));
  size_t count = 0;  // of `object`: the valid depths under the mask
  float roi_min = std::numeric_limits<float>::infinity();
  float roi_max = -roi_min;
  for (int y = clipped.y; y < clipped.y + clipped.height; ++y) {
    const float* depth_row = depth_m.ptr<float>(y);
    const uint8_t* mask_row = mask.empty() ? nullptr : mask.ptr<uint8_t>(y);
    for (int x = clipped.x; x < clipped.x + clipped.width; ++x) {
      const float d = depth_row[x];
      if (!ValidDepth(d)) continue;
      roi_min = std::min(roi_min, d);
      roi_max = std::max(roi_max, d);
      object[count] = d;
      count += mask_row == nullptr || mask_row[x] != 0 ? 1 : 0;
    }
  }
  object.resize(count);
  DepthRange mode;
  if (options.dominant_mode) {
    mode = DominantDepthMode(object, options.depth_bin_m, options.mode_window_m,
                             options.mode_min_bin_fraction);
  } else if (!object.empty()) {
    const auto [lo, hi] = std::minmax_element(object.begin(), object.end());
    mode = DepthRange{true, *lo, *hi};
  }
  if (!mode.valid) return out;
  out.m_obj = mode.min;
  out.M_obj = mode.max;
  out.d_roi = static_cast<double>(roi_max) - static_cast<double>(roi_min);
  out.lo = out.m_obj - options.alpha * out.d_roi;
  out.hi = out.M_obj + options.alpha * out.d_roi;
  out.valid = true;
  return out;
}

DynamicRegions DynamicRegions::Build(const std::vector<Instance>& instances, const cv::Mat& depth_m,
                                     const cv::Size& image_size,
                                     const DynamicFilterOptions& options) {
  CheckOptions(options);
  CheckDepth(depth_m);
  if (!depth_m.empty() && depth_m.size() != image_size) {
    throw InputError("depth image size differs from the image size of the dynamic regions");
  }
  DynamicRegions out;
  out.image_size_ = image_size;
  for (const Instance& instance : instances) {
    if (!options.Uses(instance)) continue;
    ++out.instances_used_;
    out.regions_.push_back(BuildRegion(instance, depth_m, image_size, options));
  }
  return out;
}

DynamicFilterStats DynamicRegions::Label(const std::vector<cv::KeyPoint>& keypoints,
                                         const std::vector<float>& keypoint_depth,
                                         std::vector<KeypointLabel>* labels) const {
  DETSLAM_CHECK(labels != nullptr);
  DETSLAM_CHECK_MSG(labels->size() == keypoints.size(),
                    labels->size() << " labels for " << keypoints.size() << " keypoints");
  DETSLAM_CHECK_MSG(keypoint_depth.size() == keypoints.size(),
                    keypoint_depth.size() << " depths for " << keypoints.size() << " keypoints");
  DynamicFilterStats stats;
  stats.instances_used = instances_used_;
  if (regions_.empty()) return stats;

  std::vector<cv::Point> pixels(keypoints.size());
  for (size_t i = 0; i < keypoints.size(); ++i) {
    pixels[i] = cv::Point(static_cast<int>(std::lround(keypoints[i].pt.x)),
                          static_cast<int>(std::lround(keypoints[i].pt.y)));
  }
  // Mask step first, over all instances, so that a mask hit wins over another instance's depth hit.
  for (size_t i = 0; i < keypoints.size(); ++i) {
    if ((*labels)[i] != KeypointLabel::kStatic) continue;
    for (const InstanceRegion& region : regions_) {
      if (InsideDilated(region, pixels[i])) {
        (*labels)[i] = KeypointLabel::kDynamicMask;
        ++stats.rejected_mask;
        break;
      }
    }
  }
  for (size_t i = 0; i < keypoints.size(); ++i) {
    if ((*labels)[i] != KeypointLabel::kStatic || !ValidDepth(keypoint_depth[i])) continue;
    for (const InstanceRegion& region : regions_) {
      if (region.box.contains(pixels[i]) && region.interval.Contains(keypoint_depth[i])) {
        (*labels)[i] = KeypointLabel::kDynamicDepth;
        ++stats.rejected_depth;
        break;
      }
    }
  }
  return stats;
}

cv::Mat DynamicRegions::IgnoreMask(const cv::Mat& depth_m) const {
  CheckDepth(depth_m);
  cv::Mat ignore = cv::Mat::zeros(image_size_, CV_8UC1);
  for (const InstanceRegion& region : regions_) {
    if (!region.dilated.empty()) {
      cv::Mat target = ignore(region.roi);
      cv::bitwise_or(target, region.dilated, target);
    }
    if (!region.interval.valid) continue;
    for (int y = region.box.y; y < region.box.y + region.box.height; ++y) {
      const float* depth_row = depth_m.ptr<float>(y);
      uint8_t* out_row = ignore.ptr<uint8_t>(y);
      for (int x = region.box.x; x < region.box.x + region.box.width; ++x) {
        const float d = depth_row[x];
        if (ValidDepth(d) && region.interval.Contains(d)) out_row[x] = 255;
      }
    }
  }
  return ignore;
}

DynamicFilterStats LabelDynamicKeypoints(const std::vector<cv::KeyPoint>& keypoints,
                                         const std::vector<float>& keypoint_depth,
                                         const std::vector<Instance>& instances,
                                         const cv::Mat& depth_m,
                                         const DynamicFilterOptions& options,
                                         std::vector<KeypointLabel>* labels) {
  CheckDepth(depth_m);
  const DynamicRegions regions =
      DynamicRegions::Build(instances, depth_m, InferImageSize(instances, depth_m), options);
  return regions.Label(keypoints, keypoint_depth, labels);
}

cv::Mat DynamicIgnoreMask(const std::vector<Instance>& instances, const cv::Mat& depth_m,
                          const cv::Size& image_size, const DynamicFilterOptions& options) {
  return DynamicRegions::Build(instances, depth_m, image_size, options).IgnoreMask(depth_m);
}

}  // namespace detslam
