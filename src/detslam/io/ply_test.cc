#include "detslam/io/ply.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "detslam/core/check.h"
#include "support/cli_runner.h"

namespace detslam {
namespace {
namespace fs = std::filesystem;
using Color = Eigen::Matrix<uint8_t, 3, 1>;

struct PlyFile {
  std::vector<std::string> header;  // lines up to and including end_header
  std::string body;
};

PlyFile ReadPly(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  PlyFile ply;
  std::string line;
  while (std::getline(in, line)) {
    ply.header.push_back(line);
    if (line == "end_header") break;
  }
  std::stringstream rest;
  rest << in.rdbuf();
  ply.body = rest.str();
  return ply;
}

float FloatLe(const std::string& bytes, size_t offset) {
  uint32_t bits = 0;
  for (int k = 0; k < 4; ++k) {
    bits |= static_cast<uint32_t>(static_cast<uint8_t>(bytes[offset + k])) << (8 * k);
  }
  float f = 0;
  std::memcpy(&f, &bits, sizeof(f));
  return f;
}

using testing::TempPath;

TEST(Ply, ColouredCloudHeaderAndFirstVertex) {
  const std::string path = TempPath("colour.ply");
  const std::vector<Eigen::Vector3d> points = {{1.5, -2.25, 3.0}, {0.0, 0.5, 7.0}, {4, 5, 6}};
  const std::vector<Color> colors = {Color(255, 10, 0), Color(1, 2, 3), Color(4, 5, 6)};
  WritePointCloudPly(path, points, colors);
  EXPECT_FALSE(fs::exists(path + ".tmp"));
  const PlyFile ply = ReadPly(path);
  ASSERT_GE(ply.header.size(), 3u);
  EXPECT_EQ(ply.header[0], "ply");
  EXPECT_EQ(ply.header[1], "format binary_little_endian 1.0");
  EXPECT_THAT(ply.header, ::testing::Contains("element vertex 3"));
  EXPECT_THAT(ply.header, ::testing::Contains("property uchar red"));
  EXPECT_EQ(ply.header.back(), "end_header");
  ASSERT_EQ(ply.body.size(), 3u * 15u);
  EXPECT_EQ(FloatLe(ply.body, 0), 1.5f);
  EXPECT_EQ(FloatLe(ply.body, 4), -2.25f);
  EXPECT_EQ(FloatLe(ply.body, 8), 3.0f);
  EXPECT_EQ(static_cast<uint8_t>(ply.body[12]), 255);
  EXPECT_EQ(static_cast<uint8_t>(ply.body[13]), 10);
  EXPECT_EQ(static_cast<uint8_t>(ply.body[14]), 0);
  EXPECT_EQ(FloatLe(ply.body, 15 + 8), 7.0f);  // second vertex z
  fs::remove(path);
}

TEST(Ply, UncolouredAndEmptyClouds) {
  const std::string path = TempPath("plain.ply");
  WritePointCloudPly(path, {{0.25, 0.5, -1.0}}, {});
  PlyFile ply = ReadPly(path);
  EXPECT_THAT(ply.header, ::testing::Contains("element vertex 1"));
  EXPECT_THAT(ply.header, ::testing::Not(::testing::Contains("property uchar red")));
  ASSERT_EQ(ply.body.size(), 12u);
  EXPECT_EQ(FloatLe(ply.body, 8), -1.0f);
  WritePointCloudPly(path, {}, {});
  ply = ReadPly(path);
  EXPECT_THAT(ply.header, ::testing::Contains("element vertex 0"));
  EXPECT_TRUE(ply.body.empty());
  fs::remove(path);
}

TEST(Ply, ColourCountMismatchIsAnErrorNamingTheFile) {
  const std::string path = TempPath("mismatch.ply");
  try {
    WritePointCloudPly(path, {{0, 0, 1}, {0, 0, 2}}, {Color(1, 2, 3)});
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr(path));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("2 points but 1 colours"));
  }
  EXPECT_FALSE(fs::exists(path));
}

TEST(Ply, NormalsAndColoursRoundTripThroughTheReader) {
  const std::string path = TempPath("normals.ply");
  const std::vector<Eigen::Vector3d> points = {{1.5, -2.25, 3.0}, {0.0, 0.5, 7.0}};
  const std::vector<Color> colors = {Color(255, 10, 0), Color(1, 2, 3)};
  const std::vector<Eigen::Vector3d> normals = {{0, 0, 1}, {0.6, 0.8, 0}};
  WritePointCloudPly(path, points, colors, normals);
  const PlyFile raw = ReadPly(path);
  EXPECT_THAT(raw.header, ::testing::Contains("property float nx"));
  EXPECT_EQ(raw.body.size(), 2u * 27u);
  const PointCloud cloud = ReadPointCloudPly(path);
  ASSERT_EQ(cloud.points.size(), 2u);
  ASSERT_EQ(cloud.colors.size(), 2u);
  ASSERT_EQ(cloud.normals.size(), 2u);
  EXPECT_EQ(cloud.points[0], points[0]);
  EXPECT_EQ(cloud.points[1], points[1]);
  EXPECT_EQ(cloud.colors[0], colors[0]);
  EXPECT_NEAR((cloud.normals[1] - normals[1]).norm(), 0, 1e-7);
  WritePointCloudPly(path, points, {});
  const PointCloud plain = ReadPointCloudPly(path);
  EXPECT_EQ(plain.points.size(), 2u);
  EXPECT_TRUE(plain.colors.empty());
  EXPECT_TRUE(plain.normals.empty());
  fs::remove(path);
}

TEST(Ply, ReaderNamesTheFileForTruncatedOrForeignFiles) {
  const std::string path = TempPath("cut.ply");
  WritePointCloudPly(path, {{1, 2, 3}, {4, 5, 6}}, {});
  fs::resize_file(path, fs::file_size(path) - 5);
  EXPECT_THAT([&] { ReadPointCloudPly(path); },
              ::testing::ThrowsMessage<InputError>(::testing::AllOf(
                  ::testing::HasSubstr(path), ::testing::HasSubstr("ends after 1 of 2"))));
  {
    std::ofstream out(path);
    out << "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n1\n";
  }
  EXPECT_THAT([&] { ReadPointCloudPly(path); },
              ::testing::ThrowsMessage<InputError>(::testing::AllOf(
                  ::testing::HasSubstr(path + ":2"), ::testing::HasSubstr("binary_little_endian"))));
  {
    std::ofstream out(path);
    out << "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\nend_header\n";
  }
  EXPECT_THAT([&] { ReadPointCloudPly(path); },
              ::testing::ThrowsMessage<InputError>(::testing::HasSubstr("no vertex property y")));
  EXPECT_THAT([&] { ReadPointCloudPly(TempPath("missing.ply")); },
              ::testing::ThrowsMessage<InputError>(::testing::HasSubstr("cannot open")));
  fs::remove(path);
}

}  // namespace
}  // namespace detslam
