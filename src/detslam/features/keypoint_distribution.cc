#include "detslam/features/keypoint_distribution.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace detslam {
namespace {

struct Node {
  float x0, x1, y0, y1;
  std::vector<size_t> indices;
  // A node of (almost) zero area cannot separate its keypoints any further.
  bool Splittable() const { return indices.size() > 1 && (x1 - x0) > 0.5f && (y1 - y0) > 0.5f; }
};

// Appends the non-empty quarters of `node` to `out`.
void Split(const std::vector<cv::KeyPoint>& keypoints, Node&& node, std::vector<Node>* out) {
  const float mx = 0.5f * (node.x0 + node.x1);
  const float my = 0.5f * (node.y0 + node.y1);
  Node children[4] = {{node.x0, mx, node.y0, my, {}},
                      {mx, node.x1, node.y0, my, {}},
                      {node.x0, mx, my, node.y1, {}},
                      {mx, node.x1, my, node.y1, {}}};
  for (size_t i : node.indices) {
    const cv::Point2f& p = keypoints[i].pt;
    const int child = (p.x < mx ? 0 : 1) + (p.y < my ? 0 : 2);
    children[child].indices.push_back(i);
  }
  for (Node& child : children) {
    if (!child.indices.empty()) out->push_back(std::move(child));
  }
}

}  // namespace

std::vector<size_t> DistributeQuadtree(const std::vector<cv::KeyPoint>& keypoints, float min_x,
                                       float max_x, float min_y, float max_y, int target) {
  std::vector<size_t> result;
  if (target <= 0 || keypoints.empty() || max_x <= min_x || max_y <= min_y) return result;

  // Initial nodes: side by side along x, about as many as the box's aspect ratio.
  const int num_initial =
      std::max(1, static_cast<int>(std::lround((max_x - min_x) / (max_y - min_y))));
  const float width = (max_x - min_x) / num_initial;
  std::vector<Node> nodes(num_initial);
  for (int i = 0; i < num_initial; ++i) {
    nodes[i] = {min_x + i * width,
                i + 1 == num_initial ? max_x : min_x + (i + 1) * width,
                min_y,
                max_y,
                {}};
  }
  for (size_t i = 0; i < keypoints.size(); ++i) {
    const cv::Point2f& p = keypoints[i].pt;
    if (p.x < min_x || p.x >= max_x || p.y < min_y || p.y >= max_y) continue;
    const int n = std::min(num_initial - 1, static_cast<int>((p.x - min_x) / width));
    nodes[n].indices.push_back(i);
  }
  nodes.erase(
      std::remove_if(nodes.begin(), nodes.end(), [](const Node& n) { return n.indices.empty(); }),
      nodes.end());

  const size_t wanted = static_cast<size_t>(target);
  while (nodes.size() < wanted) {
    std::vector<size_t> splittable;
    for (size_t i = 0; i < nodes.size(); ++i) {
      if (nodes[i].Splittable()) splittable.push_back(i);
    }
    if (splittable.empty()) break;
    std::vector<Node> next;
    next.reserve(nodes.size() + 3 * splittable.size());
    if (nodes.size() + 3 * splittable.size() <= wanted) {
      for (Node& node : nodes) {
        if (node.Splittable()) {
          Split(keypoints, std::move(node), &next);
        } else {
          next.push_back(std::move(node));
        }
      }
    } else {
      // A full round would overshoot: split the most populated nodes first, until enough.
      std::stable_sort(splittable.begin(), splittable.end(), [&](size_t a, size_t b) {
        return nodes[a].indices.size() > nodes[b].indices.size();
      });
      std::vector<bool> split(nodes.size(), false);
      size_t count = nodes.size();
      for (size_t i : splittable) {
        if (count >= wanted) break;
        split[i] = true;
        count += 3;  // upper bound; empty quarters are dropped, the loop continues if short
      }
      for (size_t i = 0; i < nodes.size(); ++i) {
        if (split[i]) {
          Split(keypoints, std::move(nodes[i]), &next);
        } else {
          next.push_back(std::move(nodes[i]));
        }
      }
    }
    nodes = std::move(next);
  }

  result.reserve(nodes.size());
  for (const Node& node : nodes) {
    size_t best = node.indices.front();
    for (size_t i : node.indices) {
      if (keypoints[i].response > keypoints[best].response ||
          (keypoints[i].response == keypoints[best].response && i < best)) {
        best = i;
      }
    }
    result.push_back(best);
  }
  if (result.size() > wanted) {
    std::sort(result.begin(), result.end(), [&](size_t a, size_t b) {
      if (keypoints[a].response != keypoints[b].response) {
        return keypoints[a].response > keypoints[b].response;
      }
      return a < b;
    });
    result.resize(wanted);
  }
  std::sort(result.begin(), result.end());
  return result;
}

}  // namespace detslam
