#include "detslam/place/vocabulary.h"

#include <algorithm>
#include <cmath>

#include "detslam/core/check.h"
#include "detslam/features/orb_extractor.h"

namespace detslam {

bool VocabularyOptions::Check(std::string* error) const {
  auto fail = [error](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (k < 2 || k > 1000) return fail("vocabulary k must be in [2, 1000], got " + std::to_string(k));
  if (levels < 1 || levels > 20) {
    return fail("vocabulary levels must be in [1, 20], got " + std::to_string(levels));
  }
  if (std::pow(static_cast<double>(k), levels) > 1e9) {
    return fail("vocabulary k^levels must be at most 1e9 words, got " + std::to_string(k) + "^" +
                std::to_string(levels));
  }
  if (max_iterations < 1) {
    return fail("vocabulary max_iterations must be >= 1, got " + std::to_string(max_iterations));
  }
  return true;
}

void Vocabulary::IndexNodes() {
  words_.clear();
  for (auto& node : nodes_) node.children.clear();
  for (size_t i = 1; i < nodes_.size(); ++i) nodes_[nodes_[i].parent].children.push_back(int(i));
  for (size_t i = 0; i < nodes_.size(); ++i) {
    if (!nodes_[i].is_leaf) continue;
    nodes_[i].word_id = static_cast<int>(words_.size());
    words_.push_back(static_cast<int>(i));
  }
}

int Vocabulary::WordOf(const uint8_t* descriptor, int depth, int* node_at_depth) const {
  DETSLAM_CHECK_MSG(!nodes_.empty() && !words_.empty(), "WordOf on an empty vocabulary");
  int node = 0, d = 0, at_depth = 0;
  while (!nodes_[node].is_leaf) {
    int best = -1, best_distance = 1 << 30;
    for (int child : nodes_[node].children) {
      const int distance = DescriptorDistance(descriptor, nodes_[child].descriptor.data());
      if (distance < best_distance) {  // ties: the lower node index (children are ascending)
        best_distance = distance;
        best = child;
      }
    }
    node = best;
    ++d;
    if (d <= depth) at_depth = node;
  }
  if (node_at_depth) *node_at_depth = at_depth;
  return nodes_[node].word_id;
}

BowVector Vocabulary::Transform(const cv::Mat& descriptors, FeatureVector* features,
                                int levels_up) const {
  if (!descriptors.empty() && (descriptors.type() != CV_8UC1 || descriptors.cols != 32)) {
    throw InputError("Vocabulary::Transform: descriptors must be CV_8UC1 with 32 columns");
  }
  if (features) features->clear();
  BowVector bow;
  if (descriptors.empty()) return bow;
  const int depth = std::max(0, levels_ - levels_up);
  std::map<int, int> counts;
  for (int r = 0; r < descriptors.rows; ++r) {
    int node = 0;
    const int word = WordOf(descriptors.ptr<uint8_t>(r), depth, &node);
    ++counts[word];
    if (features) (*features)[node].push_back(r);
  }
  // tf * idf, tf = count / number of features; words with idf 0 (in every training image) carry
  // no information and are left out.
  const double n = descriptors.rows;
  double sum = 0.0;
  for (const auto& [word, count] : counts) {
    const double weight = count / n * WordIdf(word);
    if (weight <= 0.0) continue;
    bow.emplace(word, weight);
    sum += weight;
  }
  if (sum > 0.0) {
    for (auto& entry : bow) entry.second /= sum;
  }
  return bow;
}

}  // namespace detslam
