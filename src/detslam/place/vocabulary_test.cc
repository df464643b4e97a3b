#include "detslam/place/vocabulary.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>

#include "detslam/core/check.h"
#include "support/cli_runner.h"

namespace detslam {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

constexpr int kCentres = 8;

std::vector<Vocabulary::Descriptor> RandomCentres(Rng& rng) {
  std::vector<Vocabulary::Descriptor> centres(kCentres);
  for (auto& c : centres) {
    for (auto& byte : c) byte = static_cast<uint8_t>(rng.UniformInt(0, 255));
  }
  return centres;
}

// `per_centre` descriptors of each listed centre, each with `flips` random bits flipped.
cv::Mat Noisy(const std::vector<Vocabulary::Descriptor>& centres, const std::vector<int>& which,
              int per_centre, Rng& rng, int flips = 6) {
  cv::Mat d(static_cast<int>(which.size()) * per_centre, 32, CV_8UC1);
  int row = 0;
  for (int c : which) {
    for (int i = 0; i < per_centre; ++i, ++row) {
      uint8_t* p = d.ptr<uint8_t>(row);
      std::copy(centres[c].begin(), centres[c].end(), p);
      for (int f = 0; f < flips; ++f) {
        const int bit = rng.UniformInt(0, 255);
        p[bit / 8] ^= static_cast<uint8_t>(1u << (bit % 8));
      }
    }
  }
  return d;
}

// Training set: image i holds descriptors of centre i only.
struct ClusterWorld {
  Rng rng{7};
  std::vector<Vocabulary::Descriptor> centres = RandomCentres(rng);
  std::vector<cv::Mat> images;
  ClusterWorld() {
    for (int c = 0; c < kCentres; ++c) images.push_back(Noisy(centres, {c}, 40, rng));
  }
};

Vocabulary TrainOn(const ClusterWorld& world, int k, int levels, uint64_t seed = 1) {
  VocabularyOptions options;
  options.k = k;
  options.levels = levels;
  Rng rng(seed);
  Vocabulary v;
  v.Train(world.images, options, rng);
  return v;
}

// The set of words each training image's descriptors land on.
std::vector<std::set<int>> WordsPerImage(const Vocabulary& v, const ClusterWorld& world) {
  std::vector<std::set<int>> words;
  for (const cv::Mat& d : world.images) {
    words.emplace_back();
    for (int r = 0; r < d.rows; ++r) words.back().insert(v.WordOf(d.ptr<uint8_t>(r)));
  }
  return words;
}

std::string ReadBytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void WriteBytes(const fs::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary) << bytes;
}

// Unique per process and test: ctest runs the tests of this file in parallel processes.
fs::path TempPath(const std::string& name) {
  const ::testing::TestInfo* test = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::string prefix = std::to_string(::getpid()) + "_" +
                             (test != nullptr ? std::string(test->name()) + "_" : std::string());
  const fs::path path = fs::path(::testing::TempDir()) / (prefix + name);
  detslam::testing::RemoveAtExit(path);
  return path;
}

TEST(VocabularyOptions, Check) {
  VocabularyOptions o;
  std::string error;
  EXPECT_TRUE(o.Check(&error));
  o.k = 1;
  EXPECT_FALSE(o.Check(&error));
  EXPECT_THAT(error, HasSubstr("k"));
  o = {};
  o.levels = 0;
  EXPECT_FALSE(o.Check(&error));
  o = {};
  o.k = 1000;
  o.levels = 6;
  EXPECT_FALSE(o.Check(&error));
  EXPECT_THAT(error, HasSubstr("k^levels"));
  o = {};
  o.max_iterations = 0;
  EXPECT_FALSE(o.Check(&error));
}

TEST(Vocabulary, TrainRejectsBadInput) {
  Vocabulary v;
  Rng rng(1);
  EXPECT_THROW(v.Train({}, VocabularyOptions{}, rng), InputError);
  EXPECT_THROW(v.Train({cv::Mat(3, 16, CV_8UC1)}, VocabularyOptions{}, rng), InputError);
  VocabularyOptions bad;
  bad.k = 1;
  EXPECT_THROW(v.Train({cv::Mat::zeros(3, 32, CV_8UC1)}, bad, rng), InputError);
}

TEST(Vocabulary, OneLevelFindsTheKnownClusters) {
  ClusterWorld world;
  const Vocabulary v = TrainOn(world, kCentres, 1);
  EXPECT_EQ(v.size(), static_cast<size_t>(kCentres));
  EXPECT_EQ(v.training_images(), kCentres);
  std::set<int> all_words;
  for (const auto& words : WordsPerImage(v, world)) {
    ASSERT_EQ(words.size(), 1u);  // one centre -> one word
    all_words.insert(*words.begin());
  }
  EXPECT_EQ(all_words.size(), static_cast<size_t>(kCentres));  // different centres, different words
  for (size_t w = 0; w < v.size(); ++w) EXPECT_NEAR(v.WordIdf(w), std::log(8.0), 1e-12);
}

TEST(Vocabulary, DeepTreeKeepsClustersApart) {
  ClusterWorld world;
  // k^levels = 27 leaves for 8 clusters: room for uneven splits (k = 2, levels = 3 has exactly 8
  // leaves, so one uneven split would merge two clusters in a leaf).
  const Vocabulary v = TrainOn(world, 3, 3);
  EXPECT_GE(v.size(), 8u);
  EXPECT_LE(v.size(), 27u);
  const auto words = WordsPerImage(v, world);
  for (int a = 0; a < kCentres; ++a) {
    for (int b = a + 1; b < kCentres; ++b) {
      for (int w : words[a]) EXPECT_EQ(words[b].count(w), 0u) << a << " and " << b;
    }
  }
  for (const auto& node : v.nodes()) EXPECT_LE(node.children.size(), 3u);
}

TEST(Vocabulary, SameSeedGivesTheSameFileByteForByte) {
  ClusterWorld world;
  int progress_calls = 0;
  VocabularyOptions options;
  options.k = 3;
  options.levels = 3;
  Rng rng_a(5), rng_b(5);
  Vocabulary a, b;
  a.Train(world.images, options, rng_a, [&](const VocabularyProgress& p) {
    EXPECT_EQ(p.levels, 3);
    EXPECT_LE(p.nodes_done, p.nodes_at_level);
    ++progress_calls;
  });
  b.Train(world.images, options, rng_b);
  EXPECT_GT(progress_calls, 3);
  const fs::path pa = TempPath("voc_a.bin"), pb = TempPath("voc_b.bin");
  a.Save(pa.string());
  b.Save(pb.string());
  EXPECT_EQ(ReadBytes(pa), ReadBytes(pb));
}

TEST(Vocabulary, ScoresSelfOneDisjointZeroOverlapBetween) {
  ClusterWorld world;
  const Vocabulary v = TrainOn(world, kCentres, 1);
  Rng rng(11);
  const BowVector a = v.Transform(Noisy(world.centres, {0, 1}, 20, rng));
  const BowVector b = v.Transform(Noisy(world.centres, {1, 2}, 20, rng));
  const BowVector c = v.Transform(Noisy(world.centres, {5, 6}, 20, rng));
  EXPECT_NEAR(L1Norm(a), 1.0, 1e-12);
  EXPECT_EQ(a.size(), 2u);
  EXPECT_NEAR(Vocabulary::Score(a, a), 1.0, 1e-12);
  EXPECT_NEAR(Vocabulary::Score(a, c), 0.0, 1e-12);
  EXPECT_NEAR(Vocabulary::Score(a, b), 0.5, 1e-9);  // equal weights, one of two words shared
  EXPECT_EQ(Vocabulary::Score(a, b), Vocabulary::Score(b, a));
  EXPECT_EQ(Vocabulary::Score(a, BowVector{}), 0.0);
  EXPECT_TRUE(v.Transform(cv::Mat()).empty());
}

TEST(Vocabulary, FeatureVectorGroupsDescriptorsOfOneCluster) {
  ClusterWorld world;
  Rng rng(3);
  const cv::Mat d = Noisy(world.centres, {0, 3, 7}, 10, rng);  // rows 0-9, 10-19, 20-29
  for (int levels_up : {0, 1}) {
    const Vocabulary v = TrainOn(world, 2, 3);
    FeatureVector fv;
    v.Transform(d, &fv, levels_up);
    std::map<int, int> group_of_row;
    int listed = 0;
    for (const auto& [node, rows] : fv) {
      EXPECT_TRUE(std::is_sorted(rows.begin(), rows.end()));
      for (int r : rows) group_of_row[r] = node;
      listed += static_cast<int>(rows.size());
    }
    EXPECT_EQ(listed, d.rows);
    for (int r = 0; r < d.rows; ++r) {
      // Rows of one centre share a node at one level above the leaves; different centres do not.
      if (r % 10 != 0 && levels_up == 1) {
        EXPECT_EQ(group_of_row[r], group_of_row[r - r % 10]) << r;
      }
      if (r >= 10) {
        EXPECT_NE(group_of_row[r], group_of_row[r - 10]) << r;
      }
    }
  }
}

TEST(Vocabulary, SaveLoadRoundTrip) {
  ClusterWorld world;
  const Vocabulary v = TrainOn(world, 3, 2);
  const fs::path p = TempPath("voc_round.bin");
  v.Save(p.string());
  Vocabulary w;
  w.Load(p.string());
  EXPECT_EQ(w.size(), v.size());
  EXPECT_EQ(w.num_nodes(), v.num_nodes());
  EXPECT_EQ(w.k(), 3);
  EXPECT_EQ(w.levels(), 2);
  EXPECT_EQ(w.training_images(), kCentres);
  Rng rng(4);
  const cv::Mat d = Noisy(world.centres, {0, 1, 2, 3}, 15, rng, 20);
  FeatureVector fv, fw;
  EXPECT_EQ(v.Transform(d, &fv, 1), w.Transform(d, &fw, 1));
  EXPECT_EQ(fv, fw);
}

class VocabularyFile : public ::testing::Test {
 protected:
  void SetUp() override {
    ClusterWorld world;
    TrainOn(world, 2, 2).Save(good_.string());
    bytes_ = ReadBytes(good_);
  }
  // Writes `bytes` to a file and expects Load to throw an InputError naming it and `what`.
  void ExpectRejected(const std::string& bytes, const std::string& what) {
    WriteBytes(bad_, bytes);
    Vocabulary v;
    try {
      v.Load(bad_.string());
      ADD_FAILURE() << "loaded a bad file; expected: " << what;
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), HasSubstr(bad_.string()));
      EXPECT_THAT(e.what(), HasSubstr(what));
    }
  }
  static void PutU32(std::string* bytes, size_t at, uint32_t value) {
    for (int i = 0; i < 4; ++i) (*bytes)[at + i] = static_cast<char>((value >> (8 * i)) & 0xFF);
  }
  // Rewrites the trailing FNV-1a 64 checksum so that only the structural checks can object.
  static void Reseal(std::string* bytes) {
    uint64_t hash = 14695981039346656037ULL;
    const size_t body = bytes->size() - 8;
    for (size_t i = 0; i < body; ++i) {
      hash = (hash ^ static_cast<uint8_t>((*bytes)[i])) * 1099511628211ULL;
    }
    for (int i = 0; i < 8; ++i) (*bytes)[body + i] = static_cast<char>((hash >> (8 * i)) & 0xFF);
  }
  fs::path good_ = TempPath("voc_good.bin"), bad_ = TempPath("voc_bad.bin");
  std::string bytes_;
};

TEST_F(VocabularyFile, MissingFile) {
  Vocabulary v;
  EXPECT_THROW(v.Load(TempPath("no_such_vocabulary.bin").string()), InputError);
}

TEST_F(VocabularyFile, TruncatedAtAnyLength) {
  for (size_t length : {size_t{0}, size_t{5}, size_t{20}, size_t{35}, size_t{36}, size_t{80},
                        bytes_.size() - 49, bytes_.size() - 8, bytes_.size() - 1}) {
    SCOPED_TRACE(length);
    ExpectRejected(bytes_.substr(0, length), length < 36 ? "truncated" : "does not match");
  }
  ExpectRejected(bytes_ + "x", "does not match");
}

TEST_F(VocabularyFile, FlippedByteFailsTheChecksum) {
  for (size_t at : {size_t{30}, bytes_.size() / 2, bytes_.size() - 9, bytes_.size() - 1}) {
    std::string bad = bytes_;
    bad[at] = static_cast<char>(bad[at] ^ 0x10);
    ExpectRejected(bad, "checksum");
  }
}

TEST_F(VocabularyFile, WrongMagicOtherVersionAbsurdCounts) {
  std::string bad = bytes_;
  bad[0] = 'X';
  ExpectRejected(bad, "wrong magic");
  bad = bytes_;
  PutU32(&bad, 8, 2);
  ExpectRejected(bad, "format version 2");
  bad = bytes_;
  PutU32(&bad, 24, 0xFFFFFFFFu);
  ExpectRejected(bad, "node count 4294967295");
  bad = bytes_;
  PutU32(&bad, 12, 0xFFFFFFFFu);  // k
  Reseal(&bad);
  ExpectRejected(bad, "k must be");
}

TEST_F(VocabularyFile, StructuralFaultsBehindAValidChecksum) {
  std::string bad = bytes_;
  PutU32(&bad, 28 + 49 * 1, 7);  // node 1's parent after itself
  Reseal(&bad);
  ExpectRejected(bad, "node 1: parent 7 out of range");
  bad = bytes_;
  bad[28 + 4] = 3;  // root's leaf flag
  Reseal(&bad);
  ExpectRejected(bad, "leaf flag 3");
  bad = bytes_;
  PutU32(&bad, 28 + 49 * 1 + 5, 12345);  // an inner node (or a leaf) with a wrong word id
  Reseal(&bad);
  ExpectRejected(bad, "word id 12345");
}

}  // namespace
}  // namespace detslam
