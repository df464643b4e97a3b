// Real data: the 50-frame freiburg2_desk clip from the TUM RGB-D benchmark (Sturm et al., IROS
// 2012, CC-BY 4.0).
#include <gtest/gtest.h>

#include <filesystem>

#include "detslam/io/dataset.h"
#include "detslam/io/settings.h"
#include "detslam/io/text_lines.h"
#include "support/shared_data.h"

namespace detslam {
namespace {
namespace fs = std::filesystem;

constexpr const char* kClip = "data/tum/rgbd_dataset_freiburg2_desk_subset50";

TEST(DataTumDataset, Fr2DeskClipOpensLoadsAndMatchesReferenceAssociation) {
  DETSLAM_REQUIRE_SHARED(kClip);
  const std::string dir = testing::SharedPath(kClip);
  const Settings settings = PresetForDataset(dir);
  EXPECT_DOUBLE_EQ(settings.camera.depth_map_factor, 5208.0);  // fr2 preset from the name
  EXPECT_DOUBLE_EQ(settings.camera.fx, 520.908620);

  const RgbdDataset dataset = RgbdDataset::Open(dir, {});
  ASSERT_EQ(dataset.size(), 50u);
  EXPECT_FALSE(dataset.groundtruth_path().empty());

  // The association equals the benchmark's own list (columns 1-4 of associate_with_gt.txt).
  const std::string reference = (fs::path(dir) / "associate_with_gt.txt").string();
  size_t row = 0;
  ForEachDataLine(reference, [&](int line, const std::vector<std::string>& fields) {
    ASSERT_GE(fields.size(), 4u) << reference << ":" << line;
    ASSERT_LT(row, dataset.size()) << reference << ":" << line;
    const RgbdFrameRef& f = dataset.frame(row);
    Timestamp rgb, depth;
    ASSERT_TRUE(ParseTimestamp(fields[0], &rgb));
    ASSERT_TRUE(ParseTimestamp(fields[2], &depth));
    EXPECT_EQ(f.rgb_stamp, rgb) << "row " << row;
    EXPECT_EQ(f.depth_stamp, depth) << "row " << row;
    EXPECT_TRUE(fs::equivalent(f.rgb_path, fs::path(dir) / fields[1])) << "row " << row;
    EXPECT_TRUE(fs::equivalent(f.depth_path, fs::path(dir) / fields[3])) << "row " << row;
    ++row;
  });
  EXPECT_EQ(row, dataset.size());

  const RgbdImages images = dataset.Load(0, settings.camera);
  ASSERT_EQ(images.bgr.cols, 640);
  ASSERT_EQ(images.bgr.rows, 480);
  int valid = 0, plausible = 0;
  for (int v = 0; v < images.depth_m.rows; ++v) {
    for (int u = 0; u < images.depth_m.cols; ++u) {
      const float d = images.depth_m.at<float>(v, u);
      if (d <= 0) continue;
      ++valid;
      if (d >= 0.5f && d <= 5.0f) ++plausible;
    }
  }
  EXPECT_GT(valid, 640 * 480 / 2);  // a desk scene: most pixels have depth
  EXPECT_GT(plausible, 0.95 * valid);
}

}  // namespace
}  // namespace detslam
