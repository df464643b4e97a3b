// The viewer used as a person would: `detslam run --viewer --paused` and `detslam view RUN_DIR`
// opened in Debian's headless Chromium; the page's own buttons and slider are used, and what the
// page drew is checked from a screenshot and from the page's state (#page-state).
#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <regex>
#include <thread>

#include "detslam/io/dataset.h"
#include "detslam/io/settings.h"
#include "detslam/io/trajectory.h"
#include "detslam/pipeline/runner.h"
#include "detslam/segmentation/mask_dir.h"
#include "detslam/viewer/live_viewer.h"
#include "integration_util.h"
#include "support/cli_runner.h"
#include "support/headless_browser.h"
#include "support/shared_data.h"

namespace detslam {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::ChildProcess;
using testing::HeadlessBrowser;
using testing::ReadFileBytes;
using testing::TempDir;

constexpr auto kWait = std::chrono::seconds(60);

// The browser for these tests: in CI (CI=true) a missing browser fails the test.
#define REQUIRE_CHROMIUM(var)                                                              \
  const std::string var = ::detslam::testing::FindChromium();                             \
  if (var.empty()) {                                                                       \
    if (::detslam::testing::InCi()) FAIL() << "no chromium-headless-shell (required in CI)"; \
    GTEST_SKIP() << "no chromium-headless-shell or chromium (apt-get install chromium-headless-shell)"; \
  }

// The viewer's address printed by the command ("viewer: http://127.0.0.1:PORT/").
std::string ViewerUrl(const fs::path& log) {
  const std::string text = ReadFileBytes(log);
  std::smatch m;
  if (!std::regex_search(text, m, std::regex("viewer: (http://127\\.0\\.0\\.1:[0-9]+/)"))) return "";
  return m[1];
}

json PageState(HeadlessBrowser& b) {
  return json::parse(b.Evaluate("document.getElementById('page-state').textContent").get<std::string>());
}

// Pixels of `image` inside the element's box (CSS pixels = screenshot pixels at scale 1).
cv::Mat Region(HeadlessBrowser& b, const cv::Mat& image, const std::string& id) {
  const json r = b.Evaluate("(() => { const r = document.getElementById('" + id +
                            "').getBoundingClientRect(); return [r.x, r.y, r.width, r.height]; })()");
  cv::Rect box(r[0].get<int>(), r[1].get<int>(), r[2].get<int>(), r[3].get<int>());
  box &= cv::Rect(0, 0, image.cols, image.rows);
  return image(box);
}

// Pixels within `tol` of the colour (BGR) in every channel.
int CountColour(const cv::Mat& bgr, cv::Vec3b colour, int tol = 40) {
  int n = 0;
  for (int y = 0; y < bgr.rows; ++y)
    for (int x = 0; x < bgr.cols; ++x) {
      const cv::Vec3b p = bgr.at<cv::Vec3b>(y, x);
      if (std::abs(p[0] - colour[0]) <= tol && std::abs(p[1] - colour[1]) <= tol &&
          std::abs(p[2] - colour[2]) <= tol)
        ++n;
    }
  return n;
}

cv::Mat Screenshot(HeadlessBrowser& b, const std::string& save_as) {
  const std::vector<uint8_t> png = b.Screenshot();
  const cv::Mat image = cv::imdecode(png, cv::IMREAD_COLOR);
  if (!save_as.empty()) cv::imwrite(save_as, image);  // for a person looking at a failure
  return image;
}

// One synthetic walking sequence with people for both tests.
const std::string& Sequence() {
  static const std::string dir = integration::WritePresetSequence("viewer_seq", "walking_xyz", 1, 60);
  return dir;
}

// The live viewer watching a run changes nothing in it, and with no page connected it takes no
// map snapshot (its only work per frame is keeping the frame's keypoints by fate).
TEST(IntegrationViewer, AnObservedRunGivesTheSameTrajectory) {
  const RgbdDataset dataset = RgbdDataset::Open(Sequence(), {});
  const Settings settings = PresetForDataset(Sequence());
  std::string trajectories[2];
  for (int watched = 0; watched < 2; ++watched) {
    RunOptions options;
    options.out_dir = TempDir(watched ? "viewer_observed" : "viewer_unobserved");
    options.max_frames = 30;
    options.slam = SlamOptionsFromSettings(settings, 7);
    LiveViewer viewer(LiveViewerOptions{});
    if (watched) options.observer = &viewer;
    MaskDirSegmenter segmenter(Sequence() + "/masks");
    const RunSummary s = detslam::Run(dataset, settings, options, nullptr, &segmenter);
    EXPECT_EQ(s.frames, 30u);
    trajectories[watched] = ReadFileBytes(fs::path(options.out_dir) / "trajectory.txt");
    if (!watched) continue;
    const ViewerCounters c = viewer.Counters();
    EXPECT_EQ(c.frames_done, 30);
    EXPECT_EQ(c.tracked, static_cast<int64_t>(s.tracked));
    EXPECT_TRUE(c.finished);
    EXPECT_EQ(viewer.map_snapshots(), 1u);  // the final one only (OnFinish)
    const auto last = viewer.Frame(-1);
    ASSERT_NE(last, nullptr);
    EXPECT_EQ(last->index, 29);
    EXPECT_TRUE(last->has_keypoints);
    EXPECT_GT(last->keypoints[static_cast<int>(KeypointFate::kMatched)].size(), 200u);
    EXPECT_EQ(viewer.Map()->trajectory.size(), s.tracked);
  }
  EXPECT_FALSE(trajectories[0].empty());
  EXPECT_EQ(trajectories[0], trajectories[1]);
}

TEST(IntegrationViewer, LiveRunIsDrawnAndSteppedFromThePageInABrowser) {
  REQUIRE_CHROMIUM(chromium);
  const fs::path out = TempDir("viewer_live_out");
  const fs::path log = out / "log.txt";
  ChildProcess run(DETSLAM_CLI_PATH,
                   {"run", "--dataset", Sequence(), "--segmenter", "gt", "--out", (out / "run").string(),
                    "--viewer", "--paused", "--no-progress",
                    // Keypoints on people detected, then rejected (drawn), not masked out before
                    // detection.
                    "--set", "Dynamic.PreMask=false"},
                   log);
  ASSERT_TRUE(run.WaitForLog("viewer: http://127.0.0.1:", kWait)) << ReadFileBytes(log);
  const std::string url = ViewerUrl(log);
  ASSERT_FALSE(url.empty()) << ReadFileBytes(log);

  HeadlessBrowser browser(chromium, url);
  ASSERT_TRUE(browser.WaitFor("typeof page === 'object' && page.connected && page.counters && page.counters.paused", kWait));
  EXPECT_TRUE(PageState(browser)["webgl"].get<bool>()) << PageState(browser).dump();
  EXPECT_EQ(PageState(browser)["counters"]["frames_done"], 0);  // paused before the first frame

  // Three presses of the page's Step button run exactly three frames.
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(browser.WaitFor("!document.getElementById('step').disabled", kWait));
    browser.Evaluate("document.getElementById('step').click()");
    ASSERT_TRUE(browser.WaitFor("page.counters.frames_done === " + std::to_string(i + 1), kWait))
        << PageState(browser).dump();
  }
  ASSERT_TRUE(browser.WaitFor("page.image_frame === 2 && page.map_updates > 0 && page.trajectory_points === 3",
                              kWait))
      << PageState(browser).dump();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the 3-D view draws on the next animation frame
  json state = PageState(browser);
  EXPECT_EQ(state["counters"]["frames_done"], 3);  // still paused: no frame ran on its own
  EXPECT_TRUE(state["counters"]["paused"].get<bool>());
  EXPECT_GT(state["keypoints_drawn"].get<int>(), 300);
  EXPECT_GT(state["points_drawn"].get<int>(), 100);
  EXPECT_GE(state["keyframes_drawn"].get<int>(), 1);
  EXPECT_GT(state["ground_truth_points"].get<int>(), 3);
  EXPECT_TRUE(state["errors"].empty()) << state.dump();
  const json counts = browser.Evaluate(
      "['matched','unmatched','mask','depth','geometric'].map(f => +document.getElementById('n-' + f).textContent)");
  EXPECT_GT(counts[0].get<int>(), 100) << counts.dump();  // matched to map points
  EXPECT_GT(counts[2].get<int>() + counts[3].get<int>(), 5) << counts.dump();  // on the people

  const cv::Mat shot = Screenshot(browser, (out / "paused.png").string());
  ASSERT_FALSE(shot.empty());
  const cv::Mat frame = Region(browser, shot, "frame");
  cv::Scalar mean, sd;
  cv::meanStdDev(frame, mean, sd);
  EXPECT_GT(sd[0] + sd[1] + sd[2], 30) << "the frame panel shows no image";
  EXPECT_GT(CountColour(frame, {64, 204, 46}), 200) << "no matched keypoints (green) drawn";
  EXPECT_GT(CountColour(frame, {54, 65, 255}) + CountColour(frame, {190, 18, 240}), 20)
      << "no rejected keypoints (red, magenta) drawn";
  const cv::Mat map = Region(browser, shot, "map3d");
  EXPECT_GT(CountColour(map, {208, 208, 208}, 30), 100) << "no map points drawn";
  EXPECT_GT(CountColour(map, {255, 163, 74}, 50), 10) << "no keyframes drawn";

  // Resume: the counters advance on their own, the run finishes and exits normally.
  browser.Evaluate("document.getElementById('resume').click()");
  ASSERT_TRUE(browser.WaitFor("page.counters.frames_done >= 10", kWait)) << PageState(browser).dump();
  const int before = PageState(browser)["counters"]["frames_done"].get<int>();
  ASSERT_TRUE(browser.WaitFor("page.counters.frames_done > " + std::to_string(before), kWait));
  EXPECT_EQ(run.Wait(kWait), 0) << ReadFileBytes(log);
  state = PageState(browser);
  EXPECT_GT(state["frames_received"].get<int>(), 5);
  EXPECT_GE(state["images_drawn"].get<int>(), 3);
  const Trajectory trajectory = ReadTumTrajectory((out / "run" / "trajectory.txt").string());
  EXPECT_EQ(trajectory.size(), 60u);  // the viewer changed nothing in the run
}

TEST(IntegrationViewer, FinishedRunIsShownByDetslamViewInABrowser) {
  REQUIRE_CHROMIUM(chromium);
  const fs::path out = TempDir("viewer_view_out");
  ASSERT_EQ(testing::RunCli("run --dataset " + Sequence() + " --segmenter gt --no-progress --out " +
                                (out / "run").string(),
                            out / "run_log.txt"),
            0)
      << ReadFileBytes(out / "run_log.txt");
  const fs::path log = out / "view_log.txt";
  ChildProcess view(DETSLAM_CLI_PATH, {"view", (out / "run").string()}, log);
  ASSERT_TRUE(view.WaitForLog("viewer: http://127.0.0.1:", kWait)) << ReadFileBytes(log);
  HeadlessBrowser browser(chromium, ViewerUrl(log));
  ASSERT_TRUE(browser.WaitFor("typeof page === 'object' && page.mode === 'run' && page.map_updates === 1 && page.image_frame === 0",
                              kWait))
      << PageState(browser).dump();
  json state = PageState(browser);
  EXPECT_EQ(state["trajectory_points"].get<int>(), 60) << state.dump();
  EXPECT_GT(state["points_drawn"].get<int>(), 500);
  EXPECT_GT(state["ground_truth_points"].get<int>(), 50);
  EXPECT_TRUE(state["counters"]["finished"].get<bool>());
  EXPECT_EQ(state["counters"]["total"], 60);
  // The slider browses the per-frame log and the dataset's images.
  browser.Evaluate("(() => { const s = document.getElementById('slider'); s.value = 40; "
                   "s.dispatchEvent(new Event('input')); })()");
  ASSERT_TRUE(browser.WaitFor("page.image_frame === 40", kWait)) << PageState(browser).dump();
  EXPECT_NE(browser.Evaluate("document.getElementById('frame-info').textContent").get<std::string>().find("frame 40"),
            std::string::npos);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const cv::Mat shot = Screenshot(browser, (out / "view.png").string());
  ASSERT_FALSE(shot.empty());
  cv::Scalar mean, sd;
  cv::meanStdDev(Region(browser, shot, "frame"), mean, sd);
  EXPECT_GT(sd[0] + sd[1] + sd[2], 30) << "the frame panel shows no image";
  const cv::Mat map = Region(browser, shot, "map3d");
  EXPECT_GT(CountColour(map, {208, 208, 208}, 30), 300) << "no map points drawn";
  // The trajectory (green) and the aligned ground truth (orange) lie on each other.
  EXPECT_GT(CountColour(map, {64, 204, 46}, 50) + CountColour(map, {0, 153, 255}, 50), 30)
      << "no trajectory drawn";
  // Ctrl-C (SIGTERM here) closes it normally.
  view.Signal(SIGTERM);
  EXPECT_EQ(view.Wait(kWait), 0) << ReadFileBytes(log);
}

}  // namespace
}  // namespace detslam
