#include "detslam/place/keyframe_database.h"

#include <gtest/gtest.h>

namespace detslam {
namespace {

TEST(KeyFrameDatabase, QueryScoresOnlySharedWordsBestFirst) {
  KeyFrameDatabase db;
  const BowVector a = {{1, 0.5}, {2, 0.5}};
  const BowVector b = {{2, 0.5}, {3, 0.5}};
  const BowVector c = {{7, 1.0}};
  db.Insert(10, a);
  db.Insert(20, b);
  db.Insert(30, c);
  EXPECT_EQ(db.size(), 3u);
  const auto results = db.Query({{1, 0.25}, {2, 0.75}}, 10);
  ASSERT_EQ(results.size(), 2u);  // 30 shares no word
  EXPECT_EQ(results[0].id, 10);
  EXPECT_NEAR(results[0].score, ScoreL1({{1, 0.25}, {2, 0.75}}, a), 1e-12);
  EXPECT_EQ(results[1].id, 20);
  EXPECT_NEAR(results[1].score, ScoreL1({{1, 0.25}, {2, 0.75}}, b), 1e-12);
  EXPECT_NEAR(db.Query(a, 1).at(0).score, 1.0, 1e-12);
  EXPECT_EQ(db.Query(a, 1).size(), 1u);
  EXPECT_TRUE(db.Query({{99, 1.0}}, 5).empty());
}

TEST(KeyFrameDatabase, TiesGoToTheLowerIdAndScaleDoesNotMatter) {
  KeyFrameDatabase db;
  db.Insert(5, {{1, 2.0}, {2, 2.0}});  // not normalised: same as 0.5 / 0.5
  db.Insert(3, {{1, 0.5}, {2, 0.5}});
  db.Insert(4, {{1, 0.5}, {2, 0.5}});
  const auto results = db.Query({{1, 1.0}, {2, 1.0}}, 3);
  ASSERT_EQ(results.size(), 3u);
  EXPECT_EQ(results[0].id, 3);
  EXPECT_EQ(results[1].id, 4);
  EXPECT_EQ(results[2].id, 5);
  for (const auto& r : results) EXPECT_NEAR(r.score, 1.0, 1e-12);
}

TEST(KeyFrameDatabase, EraseAndReinsert) {
  KeyFrameDatabase db;
  db.Insert(1, {{1, 1.0}});
  db.Insert(2, {{1, 0.5}, {2, 0.5}});
  db.Erase(1);
  db.Erase(42);  // unknown: ignored
  EXPECT_FALSE(db.Contains(1));
  EXPECT_EQ(db.KeyFramesWithWord(1), std::vector<KeyFrameDatabase::Id>{2});
  const auto results = db.Query({{1, 1.0}}, 10);
  ASSERT_EQ(results.size(), 1u);
  EXPECT_EQ(results[0].id, 2);
  EXPECT_NEAR(results[0].score, 0.5, 1e-12);
  db.Insert(2, {{3, 1.0}});  // replaces its old words
  EXPECT_TRUE(db.KeyFramesWithWord(1).empty());
  EXPECT_TRUE(db.Query({{1, 1.0}}, 10).empty());
  EXPECT_EQ(db.Query({{3, 1.0}}, 10).at(0).id, 2);
  db.Erase(2);
  EXPECT_EQ(db.size(), 0u);
  EXPECT_TRUE(db.KeyFramesWithWord(3).empty());
}

TEST(KeyFrameDatabase, QueryOptionsFilterByCommonWordsScoreAndExclusion) {
  KeyFrameDatabase db;
  db.Insert(1, {{1, 1.0}, {2, 1.0}, {3, 1.0}});  // shares 3 words with the query
  db.Insert(2, {{1, 1.0}, {9, 3.0}});            // shares 1 word
  db.Insert(3, {{1, 1.0}, {2, 1.0}, {3, 1.0}, {4, 1.0}});
  const BowVector query = {{1, 1.0}, {2, 1.0}, {3, 1.0}};
  KeyFrameDatabase::QueryOptions o;
  auto all = db.Query(query, o);
  ASSERT_EQ(all.size(), 3u);
  EXPECT_EQ(all[0].id, 1);
  EXPECT_EQ(all[0].common_words, 3);
  EXPECT_EQ(all[2].id, 2);
  EXPECT_EQ(all[2].common_words, 1);
  o.min_common_ratio = 0.8;  // more than 0.8 * 3 shared words: 1 and 3
  EXPECT_EQ(db.Query(query, o).size(), 2u);
  o.exclude = [](KeyFrameDatabase::Id id) { return id == 1; };
  const auto without_1 = db.Query(query, o);
  ASSERT_EQ(without_1.size(), 1u);
  EXPECT_EQ(without_1[0].id, 3);
  o.min_score = 0.8;  // keyframe 3 scores 0.75
  EXPECT_TRUE(db.Query(query, o).empty());
}

TEST(SharedNodeGroups, PairsTheNodesBothDirectIndexesHold) {
  const FeatureVector a = {{3, {0, 2}}, {5, {1}}, {8, {3}}};
  const FeatureVector b = {{3, {4}}, {4, {0}}, {8, {1, 2}}};
  auto groups = SharedNodeGroups(a, b);
  ASSERT_EQ(groups.size(), 2u);
  EXPECT_EQ(groups[0].a, (std::vector<int>{0, 2}));
  EXPECT_EQ(groups[0].b, (std::vector<int>{4}));
  EXPECT_EQ(groups[1].a, (std::vector<int>{3}));
  EXPECT_EQ(groups[1].b, (std::vector<int>{1, 2}));
  // Leaving out a's descriptors 0, 2 and 3 drops both groups.
  EXPECT_TRUE(SharedNodeGroups(a, b, {false, true, false, false}).empty());
}

}  // namespace
}  // namespace detslam
