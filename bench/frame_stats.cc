// Texture and missing-depth statistics of RGB-D dataset folders (TUM layout), the same measure on
// real recordings and on `detslam synth` output: FAST corners per colour image (threshold 20,
// non-max suppression) and the fraction of depth pixels that are 0. bench/bench_synth.sh runs it.
// Usage: frame_stats [--every N] DIR...   Prints one JSON object per folder, one per line.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <spdlog/spdlog.h>
#include <string>
#include <vector>

#include "detslam/core/check.h"
#include "detslam/io/dataset.h"
#include "detslam/synth/writer.h"

namespace {

nlohmann::json Summary(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  double sum = 0;
  for (double x : v) sum += x;
  return {{"min", v.front()}, {"max", v.back()}, {"mean", sum / v.size()},
          {"median", v[v.size() / 2]}};
}

}  // namespace

int main(int argc, char** argv) {
  spdlog::set_level(spdlog::level::warn);  // stdout carries the JSON lines only
  int every = 1;
  std::vector<std::string> dirs;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--every" && i + 1 < argc) {
      every = std::max(1, std::atoi(argv[++i]));
    } else {
      dirs.push_back(a);
    }
  }
  if (dirs.empty()) {
    std::cerr << "usage: frame_stats [--every N] DIR...\n";
    return 2;
  }
  try {
    for (const std::string& dir : dirs) {
      const detslam::RgbdDataset ds = detslam::RgbdDataset::Open(dir, {});
      std::vector<double> fast, missing;
      for (size_t i = 0; i < ds.size(); i += every) {
        const detslam::RgbdFrameRef& f = ds.frame(i);
        const cv::Mat bgr = cv::imread(f.rgb_path, cv::IMREAD_COLOR);
        const cv::Mat depth = cv::imread(f.depth_path, cv::IMREAD_UNCHANGED);
        if (bgr.empty()) throw detslam::InputError(f.rgb_path, 0, "cannot read the image");
        if (depth.empty()) throw detslam::InputError(f.depth_path, 0, "cannot read the image");
        fast.push_back(detslam::CountFastCorners(bgr));
        missing.push_back(detslam::MissingDepthFraction(depth));
      }
      const nlohmann::json j = {{"dir", dir},
                                {"frames", fast.size()},
                                {"fast20", Summary(fast)},
                                {"missing_depth", Summary(missing)}};
      std::cout << j.dump() << "\n";
    }
  } catch (const std::exception& e) {
    std::cerr << "frame_stats: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
