#include "detslam/eval/run_log.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "detslam/core/check.h"

namespace detslam {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::StartsWith;

constexpr const char* kFrame =
    R"({"index": 1, "stamp": 12.5, "state": "OK", "tracked": true, "method": "motion",
        "inliers": 321, "keyframe": false, "loop_closed": true, "keypoints": 998,
        "dynamic_instances": 2, "rejected_keypoints": 77, "geometric_rejected": 4,
        "segmentation_ms": 41.5, "extraction_ms": 8.25, "tracking_ms": 3.5, "mapping_ms": 0.0})";

std::string RunJson(const std::string& frames) {
  return std::string(R"({
 "dataset": "/data/walking", "settings": "settings.yaml", "mode": "threaded",
 "segmenter": "dnn:yolox_nano.onnx", "frames": 2, "frames_tracked": 1, "keyframes": 1,
 "map_points": 640, "relocalizations": 0, "loops_closed": 1, "wall_s": 0.5,
 "per_frame": [)") +
         frames + "]}\n";
}

class RunLogTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(::testing::TempDir()) / ("detslam_run_log_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Write(const std::string& text) {
    const std::string path = (dir_ / "run.json").string();
    std::ofstream(path) << text;
    return path;
  }
  std::string Error(const std::string& path) {
    try {
      ReadRunLog(path);
    } catch (const InputError& e) {
      return e.what();
    }
    ADD_FAILURE() << "no InputError for " << path;
    return "";
  }
  fs::path dir_;
};

TEST_F(RunLogTest, ReadsCountsAndFrames) {
  const std::string path = Write(RunJson(std::string(kFrame) + ", " + kFrame));
  const RunLog r = ReadRunLog(path);
  EXPECT_EQ(r.path, path);
  EXPECT_EQ(r.dataset, "/data/walking");
  EXPECT_EQ(r.mode, "threaded");
  EXPECT_EQ(r.segmenter, "dnn:yolox_nano.onnx");
  EXPECT_EQ(r.frames, 2);
  EXPECT_EQ(r.frames_tracked, 1);
  EXPECT_EQ(r.map_points, 640);
  EXPECT_EQ(r.loops_closed, 1);
  EXPECT_DOUBLE_EQ(r.TrackedFraction(), 0.5);
  EXPECT_DOUBLE_EQ(r.FramesPerSecond(), 4.0);
  ASSERT_EQ(r.per_frame.size(), 2u);
  const RunFrameLog& f = r.per_frame[1];
  EXPECT_EQ(f.index, 1);
  EXPECT_DOUBLE_EQ(f.stamp, 12.5);
  EXPECT_EQ(f.state, "OK");
  EXPECT_TRUE(f.tracked);
  EXPECT_EQ(f.method, "motion");
  EXPECT_EQ(f.inliers, 321);
  EXPECT_FALSE(f.keyframe);
  EXPECT_TRUE(f.loop_closed);
  EXPECT_EQ(f.keypoints, 998);
  EXPECT_EQ(f.dynamic_instances, 2);
  EXPECT_EQ(f.rejected_keypoints, 77);
  EXPECT_EQ(f.geometric_rejected, 4);
  EXPECT_DOUBLE_EQ(f.segmentation_ms, 41.5);
  EXPECT_DOUBLE_EQ(f.extraction_ms, 8.25);
  EXPECT_DOUBLE_EQ(f.tracking_ms, 3.5);
  EXPECT_EQ(f.map_keyframes, -1);  // not in this (older) run log
}

TEST_F(RunLogTest, ReadsTheAtlasSizeAfterEachFrame) {
  std::string frame = kFrame;
  frame.replace(frame.find("\"index\": 1,"), 11,
                "\"index\": 1, \"map_keyframes\": 17, \"map_points\": 4321,");
  const RunLog r = ReadRunLog(Write(RunJson(frame)));
  EXPECT_EQ(r.per_frame[0].map_keyframes, 17);
  EXPECT_EQ(r.per_frame[0].map_points, 4321);
  frame.replace(frame.find("4321"), 4, "\"many\"");
  EXPECT_THAT(Error(Write(RunJson(frame))), HasSubstr("map_points"));
}

TEST_F(RunLogTest, ReadsTheMapsOfTheAtlasWhereTheRunWroteThem) {
  // An older run log has no maps: main -1, frames without map.
  RunLog r = ReadRunLog(Write(RunJson(kFrame)));
  EXPECT_EQ(r.maps.main, -1);
  EXPECT_EQ(r.per_frame[0].map, -1);
  std::string frame = kFrame;
  frame.replace(frame.find("\"index\": 1,"), 11, "\"index\": 1, \"map\": 1, \"final_map\": 0,");
  std::string text = RunJson(frame);
  text.replace(text.find("\"per_frame\""), 0,
               R"("frames_in_main_map": 1, "maps": {"main": 0, "started": 2, "merged": 1,
               "left": 1, "merges": [{"frame": 685, "from": 1, "into": 0}]}, )");
  r = ReadRunLog(Write(text));
  EXPECT_EQ(r.maps.main, 0);
  EXPECT_EQ(r.maps.started, 2);
  EXPECT_EQ(r.maps.merged, 1);
  EXPECT_EQ(r.maps.left, 1);
  EXPECT_EQ(r.maps.frames_in_main, 1);
  EXPECT_EQ(r.maps.merge_frames, std::vector<int64_t>{685});
  EXPECT_EQ(r.per_frame[0].map, 1);
  EXPECT_EQ(r.per_frame[0].final_map, 0);
  text.replace(text.find("\"started\": 2"), 12, "\"started\": \"two\"");
  EXPECT_THAT(Error(Write(text)), HasSubstr("maps: key 'started' has the wrong type"));
}

TEST_F(RunLogTest, ReadsTheCameraRateBlockOfRealtimeRuns) {
  EXPECT_EQ(ReadRunLog(Write(RunJson(kFrame))).realtime.offered, 0);  // not a camera-rate run
  std::string text = RunJson(kFrame);
  text.replace(text.find("\"per_frame\""), 0,
               R"("realtime": {"offered": 300, "dropped": 201, "dropped_fraction": 0.67,
               "dropped_frames": [1, 2], "processed_fps": 9.5, "latency_ms": {"median": 150.5,
               "mean": 160, "p99": 270.25, "max": 300}}, )");
  const RunLog r = ReadRunLog(Write(text));
  EXPECT_EQ(r.realtime.offered, 300);
  EXPECT_EQ(r.realtime.dropped, 201);
  EXPECT_DOUBLE_EQ(r.realtime.processed_fps, 9.5);
  EXPECT_DOUBLE_EQ(r.realtime.latency_median_ms, 150.5);
  EXPECT_DOUBLE_EQ(r.realtime.latency_p99_ms, 270.25);
  EXPECT_DOUBLE_EQ(r.realtime.latency_max_ms, 300.0);
  EXPECT_FALSE(r.realtime.asynchronous);  // a file without the key (written before it existed)
  EXPECT_EQ(r.realtime.keyframes_mapped_in_burst, -1);  // idem
  text.replace(text.find("\"p99\": 270.25"), 13, "\"p99\": null");
  EXPECT_THAT(Error(Write(text)), HasSubstr("realtime.latency_ms: key 'p99' has the wrong type"));
}

TEST_F(RunLogTest, ReadsTheAsynchronousSegmentationCounters) {
  std::string text = RunJson(kFrame);
  text.replace(text.find("\"per_frame\""), 0,
               R"("realtime": {"offered": 300, "dropped": 20, "processed_fps": 28.5,
               "latency_ms": {"median": 40, "mean": 42, "p99": 80, "max": 90},
               "asynchronous_segmentation": true, "frames_segmented": 95,
               "mask_age_frames": {"median": 4, "mean": 4.2, "max": 11}, "keyframes_deferred": 7,
               "keyframes_stale_masks": 2, "keyframes_mapped_in_burst": 5}, )");
  const RunLog r = ReadRunLog(Write(text));
  EXPECT_TRUE(r.realtime.asynchronous);
  EXPECT_EQ(r.realtime.keyframes_mapped_in_burst, 5);
  EXPECT_EQ(r.realtime.frames_segmented, 95);
  EXPECT_EQ(r.realtime.keyframes_deferred, 7);
  EXPECT_EQ(r.realtime.keyframes_stale_masks, 2);
  EXPECT_DOUBLE_EQ(r.realtime.mask_age_median, 4.0);
  EXPECT_DOUBLE_EQ(r.realtime.mask_age_max, 11.0);
  text.replace(text.find("\"frames_segmented\": 95,"), 23, "");
  EXPECT_THAT(Error(Write(text)), HasSubstr("frames_segmented"));
}

TEST_F(RunLogTest, BadInputNamesTheFileLineAndKey) {
  EXPECT_THAT(Error((dir_ / "missing.json").string()), HasSubstr("cannot open run log"));
  // A syntax error on line 3.
  std::string path = Write("{\n \"dataset\": \"x\",\n \"mode\" \"threaded\"\n}\n");
  std::string e = Error(path);
  EXPECT_THAT(e, StartsWith(path + ":3: not valid JSON"));
  std::string text = RunJson(kFrame);
  text.replace(text.find("\"frames\": 2,"), 12, "");
  e = Error(Write(text));
  EXPECT_THAT(e, StartsWith(path + ": "));
  EXPECT_THAT(e, HasSubstr("missing key 'frames'"));
  std::string frame = kFrame;
  frame.replace(frame.find("\"tracked\": true"), 15, "\"tracked\": \"yes\"");
  EXPECT_THAT(Error(Write(RunJson(std::string(kFrame) + ", " + frame))),
              HasSubstr("per_frame[1]: key 'tracked' has the wrong type"));
  EXPECT_THAT(Error(Write("[1, 2]")), HasSubstr("must be a JSON object"));
  // A number no type can hold (found by the run_log fuzz target): an error, not an exception
  // that escapes.
  EXPECT_THAT(Error(Write(RunJson("39e9943"))), HasSubstr("not valid JSON"));
}

}  // namespace
}  // namespace detslam
