#include "detslam/map/place_candidates.h"

#include <gtest/gtest.h>

namespace detslam {
namespace {

// A keyframe whose features carry only a bag-of-words vector (the index needs nothing else).
KeyFrameId AddWithWords(Map* map, const BowVector& bow) {
  auto f = std::make_shared<FrameFeatures>();
  f->bow = bow;
  KeyFrame kf;
  kf.features = f;
  return map->AddKeyFrame(std::move(kf));
}

void Connect(Map* map, KeyFrameId a, KeyFrameId b, int weight) {
  map->keyframe(a).covisibility[b] = weight;
  map->keyframe(b).covisibility[a] = weight;
}

TEST(PlaceCandidates, KeyFramesEnterAndLeaveTheIndexWithTheMap) {
  Map map(ScaleInfo::Geometric(1.2, 8));
  const KeyFrameId first = AddWithWords(&map, {{1, 1.0}});
  const KeyFrameId a = AddWithWords(&map, {{1, 1.0}, {2, 1.0}});
  const KeyFrameId none = AddWithWords(&map, {});  // made without a vocabulary: not indexed
  EXPECT_EQ(map.place_index().size(), 2u);
  EXPECT_TRUE(map.place_index().Contains(a));
  EXPECT_FALSE(map.place_index().Contains(none));
  map.EraseKeyFrame(a);
  EXPECT_FALSE(map.place_index().Contains(a));
  EXPECT_TRUE(map.place_index().Contains(first));
}

TEST(PlaceCandidates, GroupsAccumulateOverCovisibleKeyFramesAndKeepTheirBest) {
  Map map(ScaleInfo::Geometric(1.2, 8));
  // Place A: keyframes 0 and 1 (covisible), both similar to the query; place B: keyframe 2, a bit
  // more similar than either alone but on its own; keyframe 3 unrelated.
  const KeyFrameId a0 = AddWithWords(&map, {{1, 1.0}, {2, 1.0}, {7, 2.0}});
  const KeyFrameId a1 = AddWithWords(&map, {{1, 1.0}, {2, 1.0}, {8, 2.0}});
  const KeyFrameId b = AddWithWords(&map, {{1, 1.0}, {2, 1.0}, {3, 0.5}, {9, 1.5}});
  AddWithWords(&map, {{20, 1.0}});
  Connect(&map, a0, a1, 50);
  const BowVector query = {{1, 1.0}, {2, 1.0}, {3, 1.0}};
  PlaceQueryOptions options;
  options.min_common_ratio = 0.0;  // b shares 3 words, A's keyframes 2: keep them all here
  const auto found = QueryPlaceCandidates(map, query, options);
  ASSERT_EQ(found.size(), 1u);  // B's group (its score alone) < 75% of A's accumulated score
  EXPECT_EQ(found[0].keyframe, a0);  // A's best; a0 and a1 tie, the lower id wins
  EXPECT_NEAR(found[0].group_score, 2 * found[0].score, 1e-12);
  EXPECT_LT(found[0].score, map.place_index().Query(query, 1).at(0).score);  // b scores highest
  EXPECT_EQ(map.place_index().Query(query, 1).at(0).id, b);
}

TEST(PlaceCandidates, LoopCandidatesSkipNeighboursAndFewSharedWords) {
  Map map(ScaleInfo::Geometric(1.2, 8));
  const KeyFrameId old_place = AddWithWords(&map, {{1, 1.0}, {2, 1.0}, {3, 1.0}});
  const KeyFrameId weak = AddWithWords(&map, {{1, 1.0}, {30, 5.0}});
  const KeyFrameId neighbour = AddWithWords(&map, {{1, 1.0}, {2, 1.0}, {5, 1.0}});
  const KeyFrameId current = AddWithWords(&map, {{1, 1.0}, {2, 1.0}, {3, 1.0}, {5, 0.2}});
  Connect(&map, current, neighbour, 40);
  const auto loops = LoopCandidates(map, current);
  // Not the neighbour; not the weak look-alike, which shares 1 word where the old place shares 3
  // (below 80 % of the most).
  ASSERT_EQ(loops.size(), 1u);
  EXPECT_EQ(loops[0].keyframe, old_place);
  EXPECT_GT(ScoreL1(map.keyframe(current).features->bow, map.keyframe(weak).features->bow), 0.0);
  // Without the old place, the look-alike is the best there is: no minimum score (ORB-SLAM3),
  // geometric verification decides.
  const auto rest = LoopCandidates(map, current, {old_place});
  ASSERT_EQ(rest.size(), 1u);
  EXPECT_EQ(rest[0].keyframe, weak);
}

}  // namespace
}  // namespace detslam
