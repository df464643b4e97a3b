#include "detslam/dynamic/instance_memory.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

#include "detslam/dynamic/dynamic_filter.h"

namespace detslam {
namespace {

double BoxIouOf(const cv::Rect& a, const cv::Rect& b) {
  const double inter = (a & b).area();
  const double uni = a.area() + b.area() - inter;
  return uni > 0 ? inter / uni : 0.0;
}

}  // namespace

bool DepthTrack::Follow(const Instance& previous, const cv::Mat& depth_m, Instance* followed) {
  if (previous.mask.empty() || depth_m.empty() || depth_m.type() != CV_32FC1 ||
      previous.mask.size() != depth_m.size() || previous.box.area() <= 0)
    return false;
  const cv::Rect image(0, 0, depth_m.cols, depth_m.rows);
  // The depth band of the previous mask in this frame's depth: its dominant depth mode (as the
  // filter's depth step takes it), so that the background the person has uncovered since, now
  // inside the old mask, does not count.
  std::vector<float> depths;
  int prev_area = 0;
  const cv::Rect prev_box = previous.box & image;
  for (int y = prev_box.y; y < prev_box.br().y; ++y) {
    const uint8_t* m = previous.mask.ptr<uint8_t>(y);
    const float* d = depth_m.ptr<float>(y);
    for (int x = prev_box.x; x < prev_box.br().x; ++x) {
      if (m[x] == 0) continue;
      ++prev_area;
      if (d[x] > 0.0f && std::isfinite(d[x])) depths.push_back(d[x]);
    }
  }
  if (prev_area == 0 || depths.size() < 20) return false;
  const DynamicFilterOptions filter;
  const DepthRange mode = DominantDepthMode(depths, filter.depth_bin_m, filter.mode_window_m,
                                            filter.mode_min_bin_fraction);
  if (!mode.valid) return false;
  const double lo = mode.min - kBandMarginM, hi = mode.max + kBandMarginM;
  const int gx = static_cast<int>(std::lround(kGrowFraction * prev_box.width));
  const int gy = static_cast<int>(std::lround(kGrowFraction * prev_box.height));
  const cv::Rect region =
      cv::Rect(prev_box.x - gx, prev_box.y - gy, prev_box.width + 2 * gx, prev_box.height + 2 * gy) &
      image;
  cv::Mat in_band(region.size(), CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < region.height; ++y) {
    const float* d = depth_m.ptr<float>(region.y + y);
    uint8_t* b = in_band.ptr<uint8_t>(y);
    for (int x = 0; x < region.width; ++x) {
      const float z = d[region.x + x];
      b[x] = (z > 0.0f && z >= lo && z <= hi) ? 255 : 0;
    }
  }
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(in_band, labels, stats, centroids, 8, CV_32S);
  // The component that overlaps the previous mask most.
  std::vector<int> overlap(static_cast<size_t>(n), 0);
  for (int y = 0; y < region.height; ++y) {
    const int* l = labels.ptr<int>(y);
    const uint8_t* m = previous.mask.ptr<uint8_t>(region.y + y);
    for (int x = 0; x < region.width; ++x)
      if (l[x] > 0 && m[region.x + x] != 0) ++overlap[static_cast<size_t>(l[x])];
  }
  const auto best = std::max_element(overlap.begin(), overlap.end());
  if (*best == 0) return false;
  const int label = static_cast<int>(best - overlap.begin());
  const int area = stats.at<int>(label, cv::CC_STAT_AREA);
  if (area < kMinAreaRatio * prev_area || area > kMaxAreaRatio * prev_area) return false;
  *followed = previous;
  followed->mask = cv::Mat(depth_m.size(), CV_8UC1, cv::Scalar(0));
  cv::Mat(labels == label).copyTo(followed->mask(region));
  followed->box = cv::Rect(region.x + stats.at<int>(label, cv::CC_STAT_LEFT),
                           region.y + stats.at<int>(label, cv::CC_STAT_TOP),
                           stats.at<int>(label, cv::CC_STAT_WIDTH),
                           stats.at<int>(label, cv::CC_STAT_HEIGHT));
  return true;
}

std::vector<Instance> InstanceMemory::Update(const std::vector<Instance>& current,
                                             const cv::Mat& depth_m, int frames_elapsed) {
  std::vector<Instance> out = current;
  std::vector<Remembered> next;
  for (const Instance& inst : current) next.push_back({inst, 0, 0, false});
  for (const Remembered& r : remembered_) {
    bool covered = false;
    for (const Instance& c : current) {
      if (c.class_name == r.instance.class_name && BoxIouOf(c.box, r.instance.box) >= min_iou_)
        covered = true;
    }
    if (covered) continue;
    const int age = r.age + 1, frames = r.frames + frames_elapsed;
    Instance followed;
    if (frames <= depth_track_age_ && (age == 1 || r.depth_tracked) &&
        DepthTrack::Follow(r.instance, depth_m, &followed)) {
      out.push_back(followed);
      next.push_back({std::move(followed), age, frames, true});
    } else if (age <= max_age_) {
      out.push_back(r.instance);
      next.push_back({r.instance, age, frames, false});
    }
  }
  remembered_ = std::move(next);
  return out;
}

}  // namespace detslam
