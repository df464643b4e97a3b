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

}  // namespace
}  // namespace detslam
