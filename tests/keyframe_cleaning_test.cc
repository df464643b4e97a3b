// Keyframes cleaned by the detector's own masks of their frames
// (DetSlamOptions::keyframe_clean_own_masks), driven frame by frame as the asynchronous
// segmentation would: a detector that takes 4 frames segments frames 0, 4, 8, ... and its result
// for frame j is offered before frame j + 4 is tracked. The frames themselves carry no masks, so
// the people's keypoints reach tracking and the keyframes. A keyframe made from a segmented frame
// must be cleaned when that frame's result comes: its keypoints on the people (ground-truth masks)
// labelled and without landmarks. Without the option the same run keeps landmarks on the people,
// which is what the check must be able to tell.
#include <gtest/gtest.h>

#include <cstdio>
#include <opencv2/imgproc.hpp>

#include "detslam/pipeline/slam_system.h"
#include "detslam/synth/sequence.h"

namespace detslam {
namespace {

constexpr int kDetectorFrames = 4;

// The ground-truth people of a synthetic frame as a segmenter would report them.
std::vector<Instance> PeopleOf(const SynthFrame& f) {
  std::vector<Instance> out;
  for (const SynthInstance& s : f.instances) {
    Instance i;
    i.class_name = s.label;
    i.score = s.score;
    i.box = s.box;
    i.mask = f.instance_mask == s.id;
    out.push_back(std::move(i));
  }
  return out;
}

enum class Mode { kNone, kClean };

struct CleaningCounts {
  int keyframes = 0;             // after the map's first
  int cleaned = 0;               // keyframes cleaned
  int on_people = 0;             // keyframe keypoints on a person (ground truth, with depth)
  int on_people_labelled = 0;    // of those: labelled, without a landmark
  int deferred = 0;
  int tracked = 0;
};

// Counts the keypoints of keyframe `id` that lie on a person of its frame in `rendered` (ground
// truth, with depth), and those of them labelled and without a landmark.
void CountOnPeople(const Map& map, KeyFrameId id, const std::vector<SynthFrame>& rendered,
                   int* on_people, int* labelled_without_landmark) {
  const KeyFrame& kf = map.keyframe(id);
  const SynthFrame& of = rendered[static_cast<size_t>(kf.frame_index)];
  for (size_t i = 0; i < kf.features->size(); ++i) {
    const cv::KeyPoint& kp = kf.features->keypoints[i];
    const cv::Point p(cvRound(kp.pt.x), cvRound(kp.pt.y));
    if (kf.features->depth[i] <= 0 || of.instance_mask.at<uint16_t>(p) == 0) continue;
    ++*on_people;
    const bool labelled = !kf.labels.empty() && kf.labels[i] != KeypointLabel::kStatic;
    if (labelled && kf.landmarks[i] == kNoLandmark) ++*labelled_without_landmark;
  }
}

CleaningCounts RunCleaning(Mode mode, int frames) {
  SynthOptions so;
  so.preset = "walking_xyz";
  so.seed = 5;
  so.frames = frames;
  const SyntheticSequence seq(so);
  SlamOptions options;
  options.dynamic.keyframe_clean_own_masks = mode == Mode::kClean;
  SlamSystem slam(seq.camera(), options);
  std::vector<SynthFrame> rendered;
  CleaningCounts c;
  for (int k = 0; k < seq.size(); ++k) {
    rendered.push_back(seq.Render(k));
    const SynthFrame& f = rendered.back();
    const cv::Mat depth = f.DepthMetres(seq.camera().depth_map_factor);
    const int source = k - kDetectorFrames >= 0 ? (k / kDetectorFrames - 1) * kDetectorFrames : 0;
    if (k >= kDetectorFrames && k % kDetectorFrames == 0) {
      const SynthFrame& s = rendered[static_cast<size_t>(source)];
      slam.OfferOwnMasks(source, PeopleOf(s), s.DepthMetres(seq.camera().depth_map_factor));
    }
    FrameReport report;
    const std::vector<Instance> own = PeopleOf(f);  // the first frame waits for its own masks
    Frame frame = slam.ExtractFrame(k, f.stamp, f.Gray(), depth, cv::Mat(), &report,
                                    k == 0 ? &own : nullptr);
    report.mask_source = source;
    report.mask_age = k - source;
    const KeyFrameId id = slam.TrackFrame(std::move(frame), &report);
    c.tracked += report.tracking.pose_valid ? 1 : 0;
    c.deferred += report.keyframe_deferred ? 1 : 0;
    if (report.keyframe_cleaned >= 0) {
      // The keyframe of the frame whose result was offered before this one.
      EXPECT_EQ(mode, Mode::kClean);
      EXPECT_EQ(k % kDetectorFrames, 0) << "frame " << k;
      const MapStore::ReadAccess map = slam.ReadMap();
      KeyFrameId cleaned = kNoKeyFrame;
      for (const auto& [kf_id, kf] : map->keyframes())
        if (kf.frame_index == source) cleaned = kf_id;
      EXPECT_NE(cleaned, kNoKeyFrame) << "frame " << k;
      if (cleaned != kNoKeyFrame) {
        ++c.cleaned;
        CountOnPeople(*map, cleaned, rendered, &c.on_people, &c.on_people_labelled);
      }
    }
    if (id == kNoKeyFrame) continue;
    EXPECT_TRUE(report.keyframe);
    if (k > 0) ++c.keyframes;
    if (mode == Mode::kNone) {  // cleaned keyframes are counted when cleaned
      const MapStore::ReadAccess map = slam.ReadMap();
      CountOnPeople(*map, id, rendered, &c.on_people, &c.on_people_labelled);
    }
    slam.MapKeyFrame(id, &report);
  }
  std::printf("cleaning %s: %d keyframes (%d cleaned), %d deferred; %d of %d keypoints on people labelled\n",
              mode == Mode::kClean ? "on" : "off", c.keyframes, c.cleaned, c.deferred,
              c.on_people_labelled, c.on_people);
  return c;
}

TEST(IntegrationKeyFrameCleaning, KeyFramesOfSegmentedFramesAreCleanedWhenTheirMasksCome) {
  const CleaningCounts c = RunCleaning(Mode::kClean, 60);
  EXPECT_EQ(c.tracked, 60);
  EXPECT_GE(c.cleaned, 2);
  ASSERT_GE(c.on_people, 20) << "too few keypoints on people to tell";
  EXPECT_EQ(c.on_people_labelled, c.on_people);
}

TEST(IntegrationKeyFrameCleaning, WithoutThemKeyFramesKeepThePeople) {
  const CleaningCounts c = RunCleaning(Mode::kNone, 60);
  EXPECT_EQ(c.tracked, 60);
  EXPECT_EQ(c.cleaned, 0);
  ASSERT_GE(c.on_people, 20);
  EXPECT_LT(c.on_people_labelled, c.on_people / 2);
}

}  // namespace
}  // namespace detslam
