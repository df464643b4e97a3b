// Descriptor matching: brute force with Lowe's ratio test and one-to-one resolution, and the
// rotation-consistency check shared by all of ORB-SLAM's matchers.
#pragma once

#include <opencv2/core.hpp>
#include <opencv2/core/types.hpp>
#include <vector>

namespace detslam {

constexpr int kThLow = 50;    // strict ORB distance threshold (ORB-SLAM's TH_LOW)
constexpr int kThHigh = 100;  // loose ORB distance threshold (ORB-SLAM's TH_HIGH)

struct MatchOptions {
  double ratio = 0.7;             // accept if best < ratio * second-best distance
  int max_distance = kThLow;      // accept only best distances <= this
  bool check_orientation = true;  // keep only matches in the 3 dominant rotation bins
};

// For every keypoint of a, the nearest descriptor of b (Hamming), accepted by distance and ratio;
// if several a pick the same b, the one with the smaller distance (then the lower index) stays.
// Then, with check_orientation, RotationConsistency on angle(a) - angle(b). Returns DMatch with
// queryIdx into a, trainIdx into b, sorted by queryIdx. Descriptors: CV_8UC1, N x 32.
std::vector<cv::DMatch> MatchBruteForce(const std::vector<cv::KeyPoint>& kp_a,
                                        const cv::Mat& desc_a,
                                        const std::vector<cv::KeyPoint>& kp_b,
                                        const cv::Mat& desc_b, const MatchOptions& options);

// Index groups for MatchWithinGroups: keypoints of a listed in `a` are matched only against the
// keypoints of b listed in `b` of the same group. A keypoint may appear in at most one group.
struct MatchGroup {
  std::vector<int> a;  // indices into kp_a / desc_a, ascending
  std::vector<int> b;  // indices into kp_b / desc_b, ascending
};

// MatchBruteForce restricted to pairs within the same group (e.g. descriptors under the same
// vocabulary node: a bag-of-words direct index); same acceptance, conflict and orientation rules,
// groups taken in order. MatchBruteForce is the one-group case with every index.
std::vector<cv::DMatch> MatchWithinGroups(const std::vector<cv::KeyPoint>& kp_a,
                                          const cv::Mat& desc_a,
                                          const std::vector<cv::KeyPoint>& kp_b,
                                          const cv::Mat& desc_b,
                                          const std::vector<MatchGroup>& groups,
                                          const MatchOptions& options);

// Histogram of angle differences (degrees, any range; wrapped into [0, 360)) in `bins` equal bins.
// Keeps the entries of the 3 most populated bins, except a 2nd/3rd bin holding less than 10% of
// the most populated one. Ties between bins go to the lower bin. Returns one keep flag per entry.
std::vector<bool> RotationConsistency(const std::vector<float>& angle_differences_deg,
                                      int bins = 30);

}  // namespace detslam
