// The realistic generator against real Kinect frames: FAST corners per frame and the fraction of
// pixels without depth of the TUM-like presets, measured the same way on the real TUM RGB-D frames
// in ../shared/data (Sturm et al., IROS 2012, CC-BY 4.0): fr2/desk (50 frames) and one fr3
// walking_xyz frame. Skipped locally when the data is missing, fails in CI.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "detslam/io/dataset.h"
#include "detslam/synth/sequence.h"
#include "detslam/synth/writer.h"
#include "support/shared_data.h"

namespace detslam {
namespace {

struct FrameStats {
  double fast = 0;
  double missing = 0;
};

struct Range {
  double lo = 1e300, hi = -1e300;
  double sum = 0, sum2 = 0;
  int n = 0;
  void Add(double x) {
    lo = std::min(lo, x);
    hi = std::max(hi, x);
    sum += x;
    sum2 += x * x;
    ++n;
  }
  double Sd() const {
    const double m = sum / n;
    return std::sqrt(std::max(0.0, sum2 / n - m * m));
  }
};

std::vector<FrameStats> RealFrameStats(const std::string& relative) {
  const RgbdDataset dataset = RgbdDataset::Open(testing::SharedPath(relative), {});
  std::vector<FrameStats> out;
  for (const RgbdFrameRef& f : dataset.frames()) {
    const cv::Mat bgr = cv::imread(f.rgb_path, cv::IMREAD_COLOR);
    const cv::Mat depth = cv::imread(f.depth_path, cv::IMREAD_UNCHANGED);
    EXPECT_FALSE(bgr.empty()) << f.rgb_path;
    EXPECT_FALSE(depth.empty()) << f.depth_path;
    if (bgr.empty() || depth.empty()) continue;
    out.push_back({static_cast<double>(CountFastCorners(bgr)), MissingDepthFraction(depth)});
  }
  return out;
}

TEST(DataSynthRealismTest, TexturedAndMissingDepthLikeTheRealTumFrames) {
  constexpr const char* kDesk = "data/tum/rgbd_dataset_freiburg2_desk_subset50";
  constexpr const char* kWalking = "data/tum/rgbd_dataset_freiburg3_walking_xyz_1frame";
  DETSLAM_REQUIRE_SHARED(kDesk);
  DETSLAM_REQUIRE_SHARED(kWalking);
  DETSLAM_REQUIRE_SHARED("data/people/person_1.png");
  Range real_fast, real_missing;
  for (const char* clip : {kDesk, kWalking}) {
    for (const FrameStats& s : RealFrameStats(clip)) {
      real_fast.Add(s.fast);
      real_missing.Add(s.missing);
    }
  }
  ASSERT_EQ(real_fast.n, 51);
  // The real frames themselves (a check of the measurement: 1.2k-3.6k corners, 28-37 % missing).
  EXPECT_GT(real_fast.lo, 1000);
  EXPECT_LT(real_fast.hi, 4000);
  EXPECT_GT(real_missing.lo, 0.25);
  EXPECT_LT(real_missing.hi, 0.40);

  // The TUM-like presets, realistic mode, tuning seed 1, photo people; 12 frames spread over each
  // sequence. Each preset's mean must lie inside the real frames' range, widened by one standard
  // deviation of the real frames (51 frames of two scenes; the presets look at other views).
  // The easy mode is far outside it (more texture, 3-5 % missing), which this test also shows.
  const double fast_lo = real_fast.lo - real_fast.Sd(), fast_hi = real_fast.hi + real_fast.Sd();
  const double miss_lo = real_missing.lo - real_missing.Sd();
  const double miss_hi = real_missing.hi + real_missing.Sd();
  Range preset_fast, preset_missing;
  for (const char* preset : {"static", "walking_xyz", "walking_static", "walking_rpy",
                             "walking_halfsphere", "sitting_static"}) {
    for (const SynthRealism realism : {SynthRealism::kRealistic, SynthRealism::kEasy}) {
      SynthOptions o;
      o.preset = preset;
      o.seed = 1;
      o.people_dir = testing::SharedPath("data/people");
      o.realism = realism;
      const SyntheticSequence seq(o);
      Range fast, missing;
      const int samples = realism == SynthRealism::kRealistic ? 12 : 3;
      for (int i = 0; i < samples; ++i) {
        const SynthFrame f = seq.Render((2 * i + 1) * seq.size() / (2 * samples));
        fast.Add(CountFastCorners(f.bgr));
        missing.Add(MissingDepthFraction(f.depth16));
      }
      const double mf = fast.sum / fast.n, mm = missing.sum / missing.n;
      RecordProperty(std::string(preset) + "_" + SynthRealismName(realism) + "_fast",
                     std::to_string(mf));
      RecordProperty(std::string(preset) + "_" + SynthRealismName(realism) + "_missing",
                     std::to_string(mm));
      if (realism == SynthRealism::kRealistic) {
        preset_fast.Add(mf);
        preset_missing.Add(mm);
        EXPECT_GE(mf, fast_lo) << preset;
        EXPECT_LE(mf, fast_hi) << preset;
        EXPECT_GE(mm, miss_lo) << preset;
        EXPECT_LE(mm, miss_hi) << preset;
      } else {
        EXPECT_GT(mf, real_fast.hi) << preset << " (easy)";
        EXPECT_LT(mm, 0.1) << preset << " (easy)";
      }
    }
  }
  // Over the presets together: inside the real range itself, not only the widened one.
  const double all_fast = preset_fast.sum / preset_fast.n;
  const double all_missing = preset_missing.sum / preset_missing.n;
  EXPECT_GE(all_fast, real_fast.lo);
  EXPECT_LE(all_fast, real_fast.hi);
  EXPECT_GE(all_missing, real_missing.lo);
  EXPECT_LE(all_missing, real_missing.hi);
  std::printf("real frames: FAST %.0f..%.0f (sd %.0f), missing depth %.3f..%.3f (sd %.3f); "
              "realistic presets: FAST %.0f..%.0f (mean %.0f), missing %.3f..%.3f (mean %.3f)\n",
              real_fast.lo, real_fast.hi, real_fast.Sd(), real_missing.lo, real_missing.hi,
              real_missing.Sd(), preset_fast.lo, preset_fast.hi, all_fast, preset_missing.lo,
              preset_missing.hi, all_missing);
}

}  // namespace
}  // namespace detslam
