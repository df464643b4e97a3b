#include "detslam/eval/evaluate.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <regex>

#include "detslam/core/check.h"
#include "detslam/eval/eval_test_util.h"
#include "detslam/eval/report.h"
#include "detslam/eval/svg_plot.h"

namespace detslam {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using eval_test::MakeTrajectory;
using eval_test::Wiggle;

class EvaluateFilesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(::testing::TempDir()) / ("detslam_eval_files_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string Write(const std::string& name, const std::string& text) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path) << text;
    return path;
  }
  fs::path dir_;
};

TEST_F(EvaluateFilesTest, EndToEndWithFrameListJsonTextAndSvg) {
  const Trajectory gt = MakeTrajectory(1000, 100, 400, Wiggle);
  Trajectory est = MakeTrajectory(1000, 25, 100, Wiggle);
  est.erase(est.begin() + 30, est.begin() + 40);  // 10 untracked frames
  for (StampedPose& p : est) {
    p.world_from_cam = Rigid3d(p.world_from_cam.rotation(),
                               p.world_from_cam.translation() + Eigen::Vector3d(0, 0, 0.01));
  }
  std::reverse(est.begin(), est.end());  // unsorted input is sorted on read
  const std::string gt_path = (dir_ / "gt.txt").string(), est_path = (dir_ / "est.txt").string();
  WriteTumTrajectory(gt_path, gt);
  WriteTumTrajectory(est_path, est);
  std::string rgb = "# rgb\n";
  for (int k = 0; k < 100; ++k) rgb += Timestamp::FromSeconds(1000 + k / 25.0).ToString() + " rgb/x.png\n";
  Write("rgb.txt", rgb);

  const EvalResult r = EvaluateFiles(gt_path, est_path, dir_.string(), EvalOptions{});
  EXPECT_EQ(r.ate.pairs.size(), 90u);
  EXPECT_NEAR(r.ate.error_m.rmse, 0.0, 1e-6);  // a constant offset is removed by the alignment
  EXPECT_EQ(r.coverage.frames_with_gt, 100u);
  EXPECT_EQ(r.coverage.frames_tracked, 90u);
  EXPECT_EQ(r.coverage.longest_untracked_frames, 10u);
  EXPECT_NEAR(r.coverage.longest_untracked_s, 0.4, 1e-9);
  EXPECT_EQ(r.frames_path, (dir_ / "rgb.txt").string());

  const nlohmann::json j = EvalResultToJson(r, true);
  EXPECT_EQ(j["ate"]["pairs"].get<size_t>(), 90u);
  EXPECT_DOUBLE_EQ(j["ate"]["rmse"].get<double>(), r.ate.error_m.rmse);
  EXPECT_EQ(j["ate"]["series"].size(), 90u);
  EXPECT_EQ(j["rpe"]["pairs"].get<size_t>(), r.rpe.pairs.size());
  EXPECT_DOUBLE_EQ(j["rpe"]["trans_m_per_s"]["rmse"].get<double>(), r.rpe.trans_m.rmse);
  EXPECT_DOUBLE_EQ(j["coverage"]["fraction"].get<double>(), 0.9);
  EXPECT_EQ(j["options"]["rpe_unit"], "s");

  const std::string text = FormatEvalText(r);
  EXPECT_THAT(text, HasSubstr("compared_pose_pairs 90"));
  EXPECT_THAT(text, HasSubstr("(m/s)"));
  EXPECT_THAT(text, HasSubstr("(deg/s)"));
  EXPECT_THAT(text, HasSubstr("90 of 100 frames"));

  const std::string svg_path = (dir_ / "plot.svg").string();
  WriteEvalSvg(svg_path, r);
  std::ifstream in(svg_path);
  const std::string svg((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(svg.rfind("<?xml", 0), 0u);
  EXPECT_THAT(svg, HasSubstr("</svg>"));
  for (const char* s : {"(a) Top view", "(b) ATE over time", "(c) RPE over time", "ground truth",
                        "estimate (aligned)", "time [s]", "translation error [m]",
                        "rotation [deg/s]"}) {
    EXPECT_THAT(svg, HasSubstr(s));
  }
  const auto count = [&](const std::string& what) {
    size_t n = 0;
    for (size_t p = svg.find(what); p != std::string::npos; p = svg.find(what, p + 1)) ++n;
    return n;
  };
  EXPECT_EQ(count("<polyline"), 5u);  // gt, estimate, ATE, RPE trans, RPE rot
  EXPECT_EQ(count("<text"), count("</text>"));
  EXPECT_GE(count("fill='#ff9896'"), 1u);  // the untracked stretch is shaded
  EXPECT_EQ(svg.find("nan"), std::string::npos);
  // Atomic writes leave nothing else behind.
  size_t files = 0;
  for (const auto& e : fs::directory_iterator(dir_)) files += e.is_regular_file() ? 1 : 0;
  EXPECT_EQ(files, 4u);  // gt, est, rgb.txt, plot.svg
}

TEST_F(EvaluateFilesTest, BadInputNamesTheFileAndLine) {
  const std::string gt = (dir_ / "gt.txt").string();
  WriteTumTrajectory(gt, MakeTrajectory(0, 100, 200, Wiggle));
  const std::string bad = Write("bad.txt", "# c\n1.0 0 0 0 0 0 0 1\n1.1 0 0 0 0 0 1\n");
  EXPECT_THAT([&] { EvaluateFiles(gt, bad, "", EvalOptions{}); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("bad.txt:3:")));
  const std::string dup = Write("dup.txt", "1.0 0 0 0 0 0 0 1\n1.0 1 0 0 0 0 0 1\n");
  EXPECT_THAT([&] { EvaluateFiles(gt, dup, "", EvalOptions{}); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("duplicate timestamp 1.000000")));
  const std::string two = Write("two.txt", "0.5 0 0 0 0 0 0 1\n0.6 1 0 0 0 0 0 1\n");
  EXPECT_THAT([&] { EvaluateFiles(gt, two, "", EvalOptions{}); },
              ::testing::ThrowsMessage<InputError>(
                  ::testing::AllOf(HasSubstr("two.txt"), HasSubstr("at least 3"))));
  const std::string frames = Write("frames.txt", "0.1 a.png\nx b.png\n");
  EXPECT_THAT([&] { EvaluateFiles(gt, gt, frames, EvalOptions{}); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("frames.txt:2:")));
  EXPECT_THAT([&] { EvaluateFiles(gt, (dir_ / "missing.txt").string(), "", EvalOptions{}); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("missing.txt")));
  EvalOptions bad_options;
  bad_options.max_difference_s = 0;
  EXPECT_THROW(EvaluateFiles(gt, gt, "", bad_options), InputError);
}

TEST(Evaluate, CoverageWithoutFrameListUsesGroundTruthStampsAndOffset) {
  const Trajectory gt = MakeTrajectory(100, 30, 60, Wiggle);
  Trajectory est = MakeTrajectory(90, 30, 60, Wiggle);  // estimate clock 10 s behind
  est.erase(est.begin() + 5, est.begin() + 8);
  EvalOptions options;
  options.offset_s = 10.0;
  const EvalResult r = Evaluate(gt, est, {}, options);
  EXPECT_EQ(r.coverage.frames_with_gt, 60u);
  EXPECT_EQ(r.coverage.frames_tracked, 57u);
  EXPECT_EQ(r.coverage.longest_untracked_frames, 3u);
  EXPECT_NEAR(r.ate.error_m.rmse, 0.0, 1e-9);
}

}  // namespace
}  // namespace detslam
