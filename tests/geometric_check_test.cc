// The tracker's geometric check on synthetic people that no segmenter reports: the keypoints it
// labels as movers must lie on the people far more often than chance, and on the static twin it
// must label almost nothing.
#include <gtest/gtest.h>

#include <cstdio>
#include <opencv2/imgproc.hpp>

#include "detslam/pipeline/slam_system.h"
#include "detslam/synth/sequence.h"
#include "detslam/tracking/tracker.h"

namespace detslam {
namespace {

struct CheckCounts {
  int on_people = 0;   // labelled keypoints on a person (ground-truth mask, dilated 5 px)
  int elsewhere = 0;   // labelled keypoints on the static scene
  int keypoints = 0;   // all keypoints of tracked frames
  int keypoints_on_people = 0;
  int tracked = 0;
};

CheckCounts RunGeometricCheck(bool people, int frames) {
  SynthOptions so;
  so.preset = "walking_xyz";
  so.seed = 5;
  so.frames = frames;
  so.people = people;
  const SyntheticSequence seq(so);
  SlamOptions options;
  options.dynamic.geometric.enabled = true;
  const SlamSystem extractor(seq.camera(), options);  // used for feature extraction only
  Map map(MakeScaleInfo(OrbExtractor(options.orb)));
  Tracker tracker(seq.camera(), options.tracker, options.dynamic.geometric);
  CheckCounts c;
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(11, 11));
  for (int k = 0; k < seq.size(); ++k) {
    const SynthFrame f = seq.Render(k);
    const cv::Mat gray = f.Gray(), depth = f.DepthMetres(seq.camera().depth_map_factor);
    cv::Mat on_person;
    cv::dilate(f.instance_mask > 0, on_person, kernel);
    FrameReport report;
    Frame frame = extractor.ExtractFrame(k, f.stamp, gray, depth, cv::Mat(), &report);
    const TrackingResult r = tracker.Track(map, &frame);
    if (!r.pose_valid) continue;
    ++c.tracked;
    if (r.need_keyframe) tracker.CreateKeyFrame(map, &frame);
    c.keypoints += static_cast<int>(frame.size());
    int labelled = 0;
    for (size_t i = 0; i < frame.size(); ++i) {
      const cv::Point p(cvRound(frame.features->keypoints[i].pt.x), cvRound(frame.features->keypoints[i].pt.y));
      const bool person = on_person.at<uint8_t>(p) != 0;
      c.keypoints_on_people += person ? 1 : 0;
      if (frame.labels[i] != KeypointLabel::kGeometric) continue;
      ++labelled;
      (person ? c.on_people : c.elsewhere) += 1;
    }
    EXPECT_EQ(labelled, r.geometric_rejected) << "frame " << k;
  }
  std::printf("geometric check (%s): %d labelled keypoints on people, %d elsewhere; %d of %d keypoints on people\n",
              people ? "people" : "static twin", c.on_people, c.elsewhere, c.keypoints_on_people, c.keypoints);
  return c;
}

TEST(IntegrationGeometricCheck, LabelsKeypointsOnUnreportedPeople) {
  const CheckCounts c = RunGeometricCheck(true, 90);
  EXPECT_EQ(c.tracked, 90);
  const int labelled = c.on_people + c.elsewhere;
  EXPECT_GE(c.on_people, 50) << "the check found almost no movers";
  // Measured: about half of the labelled keypoints lie on people, which carry about a fifth of
  // all keypoints (seed 5, 90 frames); require at least twice the chance rate.
  const double chance = static_cast<double>(c.keypoints_on_people) / c.keypoints;
  EXPECT_GE(c.on_people, 2.0 * chance * labelled)
      << c.on_people << " of " << labelled << " labelled keypoints on people; " << c.keypoints_on_people
      << " of " << c.keypoints << " keypoints are";
}

TEST(IntegrationGeometricCheck, LabelsAlmostNothingOnAStaticScene) {
  const CheckCounts c = RunGeometricCheck(false, 90);
  EXPECT_EQ(c.tracked, 90);
  EXPECT_LE(c.elsewhere, 0.01 * c.keypoints) << c.elsewhere << " of " << c.keypoints << " keypoints";
  EXPECT_EQ(c.on_people, 0);
}

}  // namespace
}  // namespace detslam
