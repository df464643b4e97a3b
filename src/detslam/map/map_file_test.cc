#include "detslam/map/map_file.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <random>
#include <string>

#include "detslam/core/binary_io.h"
#include "detslam/core/check.h"
#include "detslam/map/map_test_util.h"
#include "support/cli_runner.h"

namespace detslam {
namespace {

using map_test::PartsOf;
using map_test::RestoreLike;

using testing::TempPath;

std::string ReadAll(const std::string& path) { return ReadFileBytes(path, 1u << 30, "test"); }

void WriteAll(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

// Four keyframes seeing 30 points (one keyframe and one point erased, so ids have gaps), with
// bag-of-words data, labels on one keyframe, covisibility and a spanning tree.
Map MakeMap(const PinholeCamera& camera) {
  Map map(ScaleInfo::Geometric(1.2, 8));
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 30; ++i) points.emplace_back(u(rng), 0.5 * u(rng), 2.5 + u(rng));
  std::vector<KeyFrameId> kfs;
  for (int k = 0; k < 4; ++k) {
    KeyFrame kf;
    kf.frame_index = 10 * k;
    kf.stamp = Timestamp::FromSeconds(100.0 + k / 3.0);
    kf.cam_from_world = Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.05 * k, Eigen::Vector3d::UnitY())),
                                Eigen::Vector3d(-0.1 * k, 0.01 * k, 0));
    auto f = std::make_shared<FrameFeatures>();
    std::vector<cv::KeyPoint> keypoints;
    for (size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector3d pc = kf.cam_from_world * points[i];
      const Eigen::Vector2d uv = camera.Project(pc);
      keypoints.emplace_back(static_cast<float>(uv.x()), static_cast<float>(uv.y()), 31.0f,
                             static_cast<float>(i), 0.5f, static_cast<int>(i % 3));
      f->undist.push_back(uv);
      f->depth.push_back(i % 7 == 0 ? -1.0f : static_cast<float>(pc.z()));
      f->u_right.push_back(i % 7 == 0 ? -1.0f : static_cast<float>(uv.x() - camera.bf / pc.z()));
    }
    f->keypoints = keypoints;
    f->descriptors = cv::Mat(static_cast<int>(points.size()), 32, CV_8UC1);
    for (int r = 0; r < f->descriptors.rows; ++r)
      for (int c = 0; c < 32; ++c) f->descriptors.at<uint8_t>(r, c) = static_cast<uint8_t>(rng());
    f->bow = {{3 + k, 0.25}, {17, 0.5}, {400, 0.25}};
    f->bow_nodes = {{2, {0, 1, 5}}, {9, {2, 3}}};
    kf.features = f;
    if (k == 2) kf.labels.assign(points.size(), KeypointLabel::kStatic), kf.labels[4] = KeypointLabel::kGeometric;
    kfs.push_back(map.AddKeyFrame(std::move(kf)));
  }
  for (size_t i = 0; i < points.size(); ++i) {
    const LandmarkId lm = map.AddLandmark(points[i], kfs[i % 2]);
    for (KeyFrameId k : kfs) {
      if ((i + static_cast<size_t>(k)) % 5 != 0) map.AddObservation(lm, k, i);
    }
    map.landmark(lm).reference_keyframe = map.landmark(lm).observations.rbegin()->first;
    map.UpdateLandmarkGeometry(lm);
    map.landmark(lm).visible = 3 + static_cast<int>(i);
    map.landmark(lm).found = 2;
  }
  for (KeyFrameId k : kfs) map.UpdateConnections(k);
  map.EraseLandmark(7);
  map.EraseKeyFrame(kfs[1]);
  return map;
}

struct Fixture {
  PinholeCamera camera;
  MapFileExpectation expected;
  Fixture() {
    expected.camera = camera;
    expected.scale = ScaleInfo::Geometric(1.2, 8);
    expected.vocabulary_checksum = 0x1234;
  }
};

TEST(MapFile, RoundTripRestoresEveryFieldAndReencodesByteForByte) {
  Fixture fx;
  const Map map = MakeMap(fx.camera);
  const std::string path = TempPath("roundtrip.dslmap");
  SaveMapFile(path, map, fx.camera, 0x1234);
  MapFileInfo info;
  const Map loaded = LoadMapFile(path, fx.expected, &info);
  EXPECT_EQ(info.version, kMapFileVersion);
  EXPECT_EQ(info.keyframes, 3u);
  EXPECT_EQ(info.landmarks, map.NumLandmarks());
  EXPECT_EQ(info.vocabulary_checksum, 0x1234u);
  EXPECT_EQ(EncodeMapFile(loaded, fx.camera, 0x1234), ReadAll(path));  // save -> load -> save

  ASSERT_EQ(loaded.NumKeyFrames(), map.NumKeyFrames());
  EXPECT_EQ(loaded.next_keyframe_id(), map.next_keyframe_id());
  EXPECT_EQ(loaded.next_landmark_id(), map.next_landmark_id());
  EXPECT_FALSE(loaded.HasKeyFrame(1));
  EXPECT_FALSE(loaded.HasLandmark(7));
  for (const auto& [id, kf] : map.keyframes()) {
    const KeyFrame& other = loaded.keyframe(id);
    EXPECT_EQ(other.frame_index, kf.frame_index);
    EXPECT_EQ(other.stamp.ns, kf.stamp.ns);
    EXPECT_EQ(other.cam_from_world.rotation().coeffs(), kf.cam_from_world.rotation().coeffs());
    EXPECT_EQ(other.cam_from_world.translation(), kf.cam_from_world.translation());
    EXPECT_EQ(other.landmarks, kf.landmarks);
    EXPECT_EQ(other.labels, kf.labels);
    EXPECT_EQ(other.covisibility, kf.covisibility);
    EXPECT_EQ(other.parent, kf.parent);
    EXPECT_EQ(other.children, kf.children);
    EXPECT_EQ(other.features->bow, kf.features->bow);
    EXPECT_EQ(other.features->bow_nodes, kf.features->bow_nodes);
    EXPECT_EQ(other.features->depth, kf.features->depth);
    EXPECT_EQ(cv::norm(other.features->descriptors, kf.features->descriptors, cv::NORM_HAMMING), 0);
    ASSERT_NE(other.features->grid, nullptr);
    EXPECT_EQ(other.features->keypoints[5].octave, kf.features->keypoints[5].octave);
  }
  for (const auto& [id, lm] : map.landmarks()) {
    const Landmark& other = loaded.landmark(id);
    EXPECT_EQ(other.position, lm.position);
    EXPECT_EQ(other.observations, lm.observations);
    EXPECT_EQ(other.normal, lm.normal);
    EXPECT_EQ(other.max_distance, lm.max_distance);
    EXPECT_EQ(other.visible, lm.visible);
    EXPECT_EQ(other.reference_keyframe, lm.reference_keyframe);
  }
  // The place index follows: a query finds the restored keyframes.
  EXPECT_EQ(loaded.place_index().size(), 3u);
  EXPECT_EQ(loaded.place_index().Query(map.keyframe(2).features->bow, 1).at(0).id, 2);
}

TEST(MapFile, KeepsEveryMapOfTheAtlas) {
  Fixture fx;
  Map map = MakeMap(fx.camera);
  KeyFrame second = map.keyframe(2);  // a copy, as the first keyframe of a second map
  second.map_id = map.NewMapId();
  second.parent = kNoKeyFrame;
  second.children.clear();
  second.covisibility.clear();
  const KeyFrameId root = map.AddKeyFrame(second);
  const std::string path = TempPath("atlas.dslmap");
  SaveMapFile(path, map, fx.camera, 0x1234);
  const Map loaded = LoadMapFile(path, fx.expected, nullptr);
  EXPECT_EQ(loaded.map_roots(), map.map_roots());
  EXPECT_EQ(loaded.MapOf(root), 1);
  EXPECT_TRUE(loaded.IsMapRoot(root));
  EXPECT_EQ(loaded.NewMapId(), 2);
  EXPECT_EQ(EncodeMapFile(loaded, fx.camera, 0x1234), ReadAll(path));
}

// Every damaged variant of a valid file gives an InputError naming the file.
void ExpectRefused(const std::string& path, const MapFileExpectation& expected,
                   const std::string& needle) {
  try {
    LoadMapFile(path, expected);
    ADD_FAILURE() << "loaded " << path << ", expected an error with '" << needle << "'";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find(needle), std::string::npos) << what;
  }
}

TEST(MapFile, TruncatedCorruptOtherVersionAndMismatchesAreRefused) {
  Fixture fx;
  const std::string good = EncodeMapFile(MakeMap(fx.camera), fx.camera, 0x1234);
  const std::string path = TempPath("damaged.dslmap");

  for (size_t cut : {size_t(0), size_t(5), size_t(20), good.size() / 2, good.size() - 1}) {
    WriteAll(path, good.substr(0, cut));
    ExpectRefused(path, fx.expected, cut < 20 ? "truncated" : "checksum");
  }
  std::string flipped = good;
  flipped[good.size() / 3] ^= 0x10;
  WriteAll(path, flipped);
  ExpectRefused(path, fx.expected, "checksum mismatch");

  std::string wrong_magic = good;
  wrong_magic[0] = 'X';
  WriteAll(path, wrong_magic);
  ExpectRefused(path, fx.expected, "not a detslam map file");

  // Another version with a valid checksum.
  std::string other_version = good.substr(0, good.size() - 8);
  other_version[8] = 3;
  PutLE(&other_version, Fnv1a64(other_version.data(), other_version.size()), 8);
  WriteAll(path, other_version);
  ExpectRefused(path, fx.expected, "format version 3");

  WriteAll(path, good);
  MapFileExpectation other = fx.expected;
  other.camera.fx += 1.0;
  ExpectRefused(path, other, "another camera");
  other = fx.expected;
  other.scale = ScaleInfo::Geometric(1.2, 6);
  ExpectRefused(path, other, "another ORB pyramid");
  other = fx.expected;
  other.vocabulary_checksum = 0x9999;
  ExpectRefused(path, other, "another vocabulary");
  other.vocabulary_checksum = 0;
  ExpectRefused(path, other, "made with a vocabulary, this run has none");
  EXPECT_NO_THROW(LoadMapFile(path, fx.expected));
}

// A camera with no undistorted image area (found by fuzzing: it reached the keypoint grid's
// check and aborted) is refused with the file's name.
TEST(MapFile, ACameraWithNoImageAreaIsRefused) {
  Fixture fx;
  PinholeCamera bad = fx.camera;
  bad.height = 0;
  const std::string path = TempPath("bad_camera.dslmap");
  WriteAll(path, EncodeMapFile(MakeMap(fx.camera), bad, 0x1234));
  try {
    ReadMapFileInfo(path);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("no undistorted image area"), std::string::npos) << what;
    EXPECT_NE(what.find(path), std::string::npos) << what;
  }
}

// Every prefix and many single-byte changes with a recomputed checksum (so that the parser itself
// meets the damage): an InputError or a valid map, never a crash.
TEST(MapFile, DamageBehindAValidChecksumNeverCrashes) {
  Fixture fx;
  const std::string good = EncodeMapFile(MakeMap(fx.camera), fx.camera, 0x1234);
  const std::string body = good.substr(0, good.size() - 8);
  const std::string path = TempPath("fuzzed.dslmap");
  std::mt19937 rng(11);
  int refused = 0, loaded = 0;
  for (int trial = 0; trial < 400; ++trial) {
    std::string bad = body;
    if (trial % 2 == 0) {
      bad.resize(std::uniform_int_distribution<size_t>(8, body.size() - 1)(rng));
    } else {
      const size_t at = std::uniform_int_distribution<size_t>(12, body.size() - 1)(rng);
      bad[at] = static_cast<char>(rng());
    }
    PutLE(&bad, Fnv1a64(bad.data(), bad.size()), 8);
    WriteAll(path, bad);
    try {
      LoadMapFile(path, fx.expected);
      ++loaded;
    } catch (const InputError&) {
      ++refused;
    }
  }
  EXPECT_EQ(refused + loaded, 400);
  EXPECT_GE(refused, 200);  // every truncation at least
}

TEST(MapRestore, RefusesPartsThatBreakTheMapsInvariants) {
  Fixture fx;
  const Map map = MakeMap(fx.camera);
  {
    auto [k, l] = PartsOf(map);
    EXPECT_NO_THROW(RestoreLike(map, k, l));
  }
  {
    auto [k, l] = PartsOf(map);
    l[0].observations[1] = 0;  // keyframe 1 was erased
    EXPECT_THROW(RestoreLike(map, k, l), InputError);
  }
  {
    auto [k, l] = PartsOf(map);
    l[1].observations = l[0].observations;  // the same slots twice
    EXPECT_THROW(RestoreLike(map, k, l), InputError);
  }
  {
    auto [k, l] = PartsOf(map);
    k[0].covisibility[3] += 1;  // no matching reverse edge
    EXPECT_THROW(RestoreLike(map, k, l), InputError);
  }
  {
    auto [k, l] = PartsOf(map);
    k[1].parent = 1;  // erased
    EXPECT_THROW(RestoreLike(map, k, l), InputError);
  }
  {
    auto [k, l] = PartsOf(map);
    std::swap(k[0], k[1]);  // ids not ascending
    EXPECT_THROW(RestoreLike(map, k, l), InputError);
  }
  {
    auto [k, l] = PartsOf(map);  // a next id that would make the first new keyframe allocate terabytes
    EXPECT_THROW(Map::Restore(map.scale(), k, l, int64_t(1) << 40, map.next_landmark_id()),
                 InputError);
    EXPECT_THROW(Map::Restore(map.scale(), k, l, map.next_keyframe_id(), int64_t(1) << 40),
                 InputError);
  }
}

}  // namespace
}  // namespace detslam
