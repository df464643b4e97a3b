// ORB extraction and matching speed on a real 640x480 TUM frame (single thread).
// Usage: detslam_bench_orb [--benchmark_...]; the image is read from
// $DETSLAM_SHARED/data/tum/... (default: the configured shared folder).
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "detslam/features/matcher.h"
#include "detslam/features/orb_extractor.h"
#include "kernel_bench_main.h"

namespace {

constexpr const char* kFrameA =
    "data/tum/rgbd_dataset_freiburg2_desk_subset50/rgb/1311868164.363181.png";
constexpr const char* kFrameB =
    "data/tum/rgbd_dataset_freiburg2_desk_subset50/rgb/1311868164.399026.png";

cv::Mat LoadGray(const char* relative) {
  const char* env = std::getenv("DETSLAM_SHARED");
  const std::string root = env != nullptr && *env != '\0' ? env : DETSLAM_SHARED_DIR_DEFAULT;
  return cv::imread(root + "/" + relative, cv::IMREAD_GRAYSCALE);
}

// The Det-SLAM stage's ignore mask of two people (about a quarter of the image), or none.
cv::Mat TwoPeopleMask(const cv::Size& size) {
  cv::Mat mask = cv::Mat::zeros(size, CV_8UC1);
  for (int x : {200, 450}) {
    cv::ellipse(mask, {x, 300}, {80, 180}, 0, 0, 360, cv::Scalar(255), cv::FILLED);
    cv::circle(mask, {x, 110}, 45, cv::Scalar(255), cv::FILLED);
  }
  return mask;
}

// Extraction without a mask, and with the two people's (cells the mask covers get no
// low-threshold retry).
void BM_OrbExtract(benchmark::State& state, bool two_people) {
  cv::setNumThreads(1);  // single-threaded figure: no OpenCV worker threads
  const cv::Mat gray = LoadGray(kFrameA);
  if (gray.empty()) {
    state.SkipWithError("shared TUM frame not found (set DETSLAM_SHARED)");
    return;
  }
  const cv::Mat mask = two_people ? TwoPeopleMask(gray.size()) : cv::Mat();
  const detslam::OrbExtractor extractor{detslam::OrbOptions{}};
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  for (auto _ : state) {
    extractor.Extract(gray, mask, &keypoints, &descriptors);
    benchmark::DoNotOptimize(descriptors.data);
  }
  state.counters["keypoints"] = static_cast<double>(keypoints.size());
  state.counters["masked_fraction"] =
      mask.empty() ? 0.0
                   : static_cast<double>(cv::countNonZero(mask)) / static_cast<double>(mask.total());
}
BENCHMARK_CAPTURE(BM_OrbExtract, no_mask, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_OrbExtract, two_people, true)->Unit(benchmark::kMillisecond);

void BM_MatchBruteForce(benchmark::State& state) {
  cv::setNumThreads(1);
  const cv::Mat a = LoadGray(kFrameA), b = LoadGray(kFrameB);
  if (a.empty() || b.empty()) {
    state.SkipWithError("shared TUM frames not found (set DETSLAM_SHARED)");
    return;
  }
  const detslam::OrbExtractor extractor{detslam::OrbOptions{}};
  std::vector<cv::KeyPoint> kp_a, kp_b;
  cv::Mat desc_a, desc_b;
  extractor.Extract(a, cv::Mat(), &kp_a, &desc_a);
  extractor.Extract(b, cv::Mat(), &kp_b, &desc_b);
  std::vector<cv::DMatch> matches;
  for (auto _ : state) {
    matches = detslam::MatchBruteForce(kp_a, desc_a, kp_b, desc_b, detslam::MatchOptions{});
    benchmark::DoNotOptimize(matches.data());
  }
  state.counters["matches"] = static_cast<double>(matches.size());
}
BENCHMARK(BM_MatchBruteForce)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) { return detslam::bench::RunKernelBenchmarks(argc, argv); }
