#include "detslam/segmentation/yolox_decode.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace detslam {
namespace {

constexpr int kSide = 64;  // 8x8 + 4x4 + 2x2 = 84 cells
constexpr int kClasses = 3;
constexpr int kCols = 5 + kClasses;

// Index of cell (gx, gy) of the grid with `stride` in the output.
int Row(int stride, int gx, int gy) {
  int row = 0;
  for (int s : {8, 16, 32}) {
    const int n = kSide / s;
    if (s == stride) return row + gy * n + gx;
    row += n * n;
  }
  return -1;
}

void SetCell(std::vector<float>* t, int row, float dx, float dy, float w, float h, float obj,
             std::vector<float> cls) {
  float* p = t->data() + row * kCols;
  p[0] = dx;
  p[1] = dy;
  p[2] = std::log(w);
  p[3] = std::log(h);
  p[4] = obj;
  for (int c = 0; c < kClasses; ++c) p[5 + c] = cls[c];
}

TEST(YoloxDecode, OutputRowsOverThreeStrides) {
  EXPECT_EQ(YoloxOutputRows(416), 3549);
  EXPECT_EQ(YoloxOutputRows(640), 8400);
  EXPECT_EQ(YoloxOutputRows(kSide), 84);
  EXPECT_EQ(YoloxOutputRows(100), 0);
}

TEST(YoloxDecode, DecodesGridOffsetsSizesAndLetterboxScale) {
  std::vector<float> t(YoloxOutputRows(kSide) * kCols, 0.0f);
  // Stride 16, cell (1, 2): centre (1.5 * 16, 2.25 * 16) = (24, 36), size (2*16, 3*16) = (32, 48).
  SetCell(&t, Row(16, 1, 2), 0.5f, 0.25f, 2.0f, 3.0f, 0.9f, {0.1f, 0.8f, 0.2f});
  // Stride 32, cell (1, 0), class 2: centre (48, 16), size (32, 32); score 0.5 * 0.9.
  SetCell(&t, Row(32, 1, 0), 0.5f, 0.5f, 1.0f, 1.0f, 0.5f, {0.0f, 0.1f, 0.9f});
  // Below the threshold: 0.9 * 0.3 = 0.27.
  SetCell(&t, Row(8, 3, 3), 0.5f, 0.5f, 1.0f, 1.0f, 0.9f, {0.3f, 0.0f, 0.0f});
  const double scale = 0.5;  // network pixels = image pixels * 0.5
  const auto dets = DecodeYolox(t.data(), YoloxOutputRows(kSide), kCols, kSide, scale, 0.35f);
  ASSERT_EQ(dets.size(), 2u);
  EXPECT_EQ(dets[0].class_id, 1);
  EXPECT_NEAR(dets[0].score, 0.72f, 1e-6);
  EXPECT_NEAR(dets[0].box.x, (24 - 16) / scale, 1e-4);
  EXPECT_NEAR(dets[0].box.y, (36 - 24) / scale, 1e-4);
  EXPECT_NEAR(dets[0].box.width, 32 / scale, 1e-4);
  EXPECT_NEAR(dets[0].box.height, 48 / scale, 1e-4);
  EXPECT_EQ(dets[1].class_id, 2);
  EXPECT_NEAR(dets[1].score, 0.45f, 1e-6);
  EXPECT_NEAR(dets[1].box.x, (48 - 16) / scale, 1e-4);
  EXPECT_NEAR(dets[1].box.y, 0.0, 1e-4);
}

TEST(YoloxDecode, NmsSuppressesOnlyWithinAClass) {
  std::vector<RawDetection> in = {
      {0, 0.6f, cv::Rect2d(10, 10, 100, 200)},
      {0, 0.9f, cv::Rect2d(12, 8, 100, 200)},  // same class, IoU ~0.94: keeps the 0.9 one
      {1, 0.5f, cv::Rect2d(11, 9, 100, 200)},  // other class, same place: kept
      {0, 0.4f, cv::Rect2d(300, 10, 50, 50)},  // same class, disjoint: kept
  };
  const auto out = NmsPerClass(in, 0.35f, 0.45f);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_FLOAT_EQ(out[0].score, 0.9f);
  EXPECT_EQ(out[1].class_id, 1);
  EXPECT_FLOAT_EQ(out[2].score, 0.4f);
}

TEST(YoloxDecode, LetterboxScalesIntoTopLeftAndPadsWith114) {
  cv::Mat img(50, 100, CV_8UC3, cv::Scalar(10, 20, 30));
  double scale = 0;
  const cv::Mat boxed = LetterboxTopLeft(img, kSide, &scale);
  EXPECT_DOUBLE_EQ(scale, 0.64);
  ASSERT_EQ(boxed.size(), cv::Size(kSide, kSide));
  EXPECT_EQ(boxed.at<cv::Vec3b>(0, 0), cv::Vec3b(10, 20, 30));
  EXPECT_EQ(boxed.at<cv::Vec3b>(31, 63), cv::Vec3b(10, 20, 30));  // 50 * 0.64 = 32 rows of image
  EXPECT_EQ(boxed.at<cv::Vec3b>(32, 0), cv::Vec3b(114, 114, 114));
  EXPECT_EQ(boxed.at<cv::Vec3b>(63, 63), cv::Vec3b(114, 114, 114));
}

}  // namespace
}  // namespace detslam
