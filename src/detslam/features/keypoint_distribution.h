// Even spatial spread of keypoints by quadtree subdivision (ORB-SLAM's octree distribution idea).
#pragma once

#include <cstddef>
#include <opencv2/core.hpp>
#include <vector>

namespace detslam {

// Splits the box [min_x, max_x) x [min_y, max_y) into nodes, starting from about square root
// nodes side by side, and splits every node holding more than one keypoint into four (empty
// children are dropped) until there are at least `target` nodes or no node can be split; when a
// full round would overshoot, the most populated nodes are split first. Each node then keeps its
// highest-response keypoint (ties: the lower index); if more than `target` remain, the strongest
// `target` are kept. Returns indices into `keypoints`, ascending. Keypoints outside the box are
// ignored. Deterministic.
std::vector<size_t> DistributeQuadtree(const std::vector<cv::KeyPoint>& keypoints, float min_x,
                                       float max_x, float min_y, float max_y, int target);

}  // namespace detslam
