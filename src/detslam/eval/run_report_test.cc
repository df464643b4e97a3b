#include "detslam/eval/run_report.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "detslam/core/check.h"
#include "detslam/eval/eval_test_util.h"

namespace detslam {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

size_t Count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}

// 20 frames; frames 5-7 without pose; keyframes 0 and 10; a loop closed at 15; people in 8-12.
RunLog HandLog() {
  RunLog r;
  r.path = "out/run.json";
  r.dataset = "data/<walk & talk>";
  r.settings = "settings.yaml";
  r.mode = "sequential";
  r.segmenter = "gt";
  r.frames = 20;
  r.frames_tracked = 17;
  r.keyframes = 2;
  r.map_points = 900;
  r.loops_closed = 1;
  r.wall_s = 2.0;
  for (int i = 0; i < 20; ++i) {
    RunFrameLog f;
    f.index = i;
    f.stamp = 100 + i / 30.0;
    f.tracked = i < 5 || i > 7;
    f.state = f.tracked ? "OK" : "LOST";
    f.inliers = f.tracked ? 300 + i : 0;
    f.keypoints = 1000;
    f.keyframe = i == 0 || i == 10;
    f.loop_closed = i == 15;
    f.dynamic_instances = (i >= 8 && i <= 12) ? 2 : 0;
    f.rejected_keypoints = f.dynamic_instances * 40;
    f.geometric_rejected = i == 9 ? 12 : 0;
    f.segmentation_ms = 40 + i;
    f.extraction_ms = 8;
    f.tracking_ms = 3;
    f.mapping_ms = f.keyframe ? 50 : 0;
    r.per_frame.push_back(f);
  }
  return r;
}

TEST(RunReport, PerFrameFigureHasItsPanelsLinesAndMarks) {
  const std::string svg = RenderRunSvg(HandLog());
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_THAT(svg, HasSubstr("</svg>"));
  for (const char* s : {"(a) Tracking", "(b) Dynamic objects", "(c) Time per frame",
                        "landmark inliers", "geometric check", "segmentation"}) {
    EXPECT_THAT(svg, HasSubstr(s));
  }
  EXPECT_EQ(Count(svg, "<polyline"), 9u);           // 2 tracking, 3 dynamic, 4 timing lines
  EXPECT_EQ(Count(svg, "fill='#ff9896'"), 1u);      // one run of frames without pose
  EXPECT_EQ(Count(svg, "stroke='#2ca02c'/>"), 2u);  // two keyframe ticks
  EXPECT_THAT(svg, HasSubstr("loop closed at frame 15"));
  EXPECT_EQ(Count(svg, "<text"), Count(svg, "</text>"));
  EXPECT_EQ(svg.find("nan"), std::string::npos);
}

TEST(RunReport, ShowsTheMapOfEveryFrameTheMergesAndTheLostStretches) {
  RunLog run = HandLog();
  EXPECT_THAT(RenderHtmlReport(run, nullptr), Not(HasSubstr("maps (atlas)")));  // older log
  for (RunFrameLog& f : run.per_frame) f.map = !f.tracked ? -1 : f.index < 5 ? 0 : 1;
  run.maps.main = 0;
  run.maps.started = 2;
  run.maps.merged = 1;
  run.maps.left = 1;
  run.maps.frames_in_main = 17;
  run.maps.merge_frames = {14};
  const std::string svg = RenderRunSvg(run);
  EXPECT_THAT(svg, HasSubstr("frame 3: map 0"));
  EXPECT_THAT(svg, HasSubstr("frame 12: map 1"));
  EXPECT_THAT(svg, Not(HasSubstr("frame 6: map")));  // no pose
  EXPECT_THAT(svg, HasSubstr("maps merged at frame 14"));
  const std::string html = RenderHtmlReport(run, nullptr);
  EXPECT_THAT(html, HasSubstr("started 2, merged 1, left 1; trajectory.txt (map 0): 17 frames"));
  EXPECT_THAT(html, HasSubstr("5-7 (3)"));
}

TEST(RunReport, HtmlWithoutGroundTruthSummarisesTheRun) {
  const std::string html = RenderHtmlReport(HandLog(), nullptr);
  EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_THAT(html, HasSubstr("17 / 20 (85.0 %); longest run without pose: 3 frames"));
  EXPECT_THAT(html, HasSubstr("class='bad'"));  // not every frame tracked
  EXPECT_THAT(html, HasSubstr("2 / 900"));
  EXPECT_THAT(html, HasSubstr("10.0 frames/s"));
  EXPECT_THAT(html, HasSubstr("segmentation 49.5"));  // median of 40..59
  EXPECT_THAT(html, HasSubstr("data/&lt;walk &amp; talk&gt;"));
  EXPECT_THAT(html, Not(HasSubstr("<walk")));
  EXPECT_THAT(html, HasSubstr("No ground truth given"));
  EXPECT_THAT(html, HasSubstr("(a) Tracking"));
  EXPECT_THAT(html, HasSubstr("</html>"));
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_THAT(html, Not(HasSubstr("camera rate")));  // not a --realtime run
}

TEST(RunReport, ACameraRateRunShowsItsDropsAndLatency) {
  RunLog log = HandLog();
  log.realtime.offered = 60;
  log.realtime.dropped = 40;
  log.realtime.processed_fps = 10;
  log.realtime.latency_median_ms = 150;
  log.realtime.latency_p99_ms = 270.5;
  log.realtime.latency_max_ms = 300;
  const std::string html = RenderHtmlReport(log, nullptr);
  EXPECT_THAT(html, HasSubstr("60 frames offered, 40 dropped (66.7 %)"));
  EXPECT_THAT(html, HasSubstr("median 150.0 ms, 99th percentile 270.5 ms, max 300.0 ms"));
  EXPECT_THAT(html, Not(HasSubstr("asynchronous segmentation")));
  EXPECT_THAT(html, Not(HasSubstr("while more waited")));  // an older file without the count
  log.realtime.keyframes_mapped_in_burst = 6;
  EXPECT_THAT(RenderHtmlReport(log, nullptr),
              HasSubstr("6 keyframes mapped without fusion or bundle adjustment while more waited"));
  log.realtime.asynchronous = true;
  log.realtime.frames_segmented = 18;
  log.realtime.mask_age_median = 4;
  log.realtime.mask_age_max = 9;
  log.realtime.keyframes_deferred = 3;
  log.realtime.keyframes_stale_masks = 1;
  EXPECT_THAT(RenderHtmlReport(log, nullptr),
              HasSubstr("18 frames segmented; masks carried to each frame were 4 frames old "
                        "(median; max 9); 3 keyframes deferred for stale masks, 1 made with stale "
                        "masks after waiting"));
}

TEST(RunReport, HtmlWithEvaluationEmbedsTheAccuracyFigure) {
  using eval_test::MakeTrajectory;
  const Trajectory gt = MakeTrajectory(100, 30, 60, eval_test::Wiggle);
  const Trajectory est = MakeTrajectory(100, 30, 60, [](double t) {
    Rigid3d p = eval_test::Wiggle(t);
    return Rigid3d(p.rotation(), p.translation() + Eigen::Vector3d(0.004 * std::sin(9 * t), 0, 0));
  });
  EvalOptions options;
  const EvalResult eval = Evaluate(gt, est, {}, options);
  const std::string html = RenderHtmlReport(HandLog(), &eval);
  EXPECT_THAT(html, HasSubstr("ATE (mm)"));
  char rmse[32];
  std::snprintf(rmse, sizeof(rmse), "<td>%.1f</td>", 1000 * eval.ate.error_m.rmse);
  EXPECT_THAT(html, HasSubstr(rmse));
  EXPECT_THAT(html, HasSubstr("(a) Top view"));
  EXPECT_EQ(html.find("<?xml"), std::string::npos);  // the figure is inlined without its prolog
  EXPECT_EQ(Count(html, "<svg"), 2u);
  EXPECT_THAT(html, Not(HasSubstr("No ground truth given")));
}

TEST(RunReport, WritesAtomically) {
  const fs::path dir =
      fs::path(::testing::TempDir()) / ("detslam_report_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string path = (dir / "report.html").string();
  WriteHtmlReport(path, HandLog(), nullptr);
  std::ifstream in(path);
  const std::string html((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_THAT(html, HasSubstr("</html>"));
  size_t files = 0;
  for (const auto& e : fs::directory_iterator(dir)) files += e.is_regular_file() ? 1 : 0;
  EXPECT_EQ(files, 1u);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace detslam
