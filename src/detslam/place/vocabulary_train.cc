// Vocabulary::Train: hierarchical k-majority clustering, level by level, then idf weights.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "detslam/core/check.h"
#include "detslam/features/orb_extractor.h"
#include "detslam/place/vocabulary.h"

namespace detslam {
namespace {

using Descriptor = Vocabulary::Descriptor;

struct Cluster {
  Descriptor centre{};
  std::vector<int> members;  // indices into the training descriptors
};

int Distance(const Descriptor& a, const Descriptor& b) {
  return DescriptorDistance(a.data(), b.data());
}

// Per-bit majority of the members (a tie gives 0).
Descriptor Majority(const std::vector<Descriptor>& all, const std::vector<int>& members) {
  int ones[256] = {};
  for (int m : members) {
    for (int byte = 0; byte < 32; ++byte) {
      const uint8_t value = all[m][byte];
      for (int bit = 0; bit < 8; ++bit) ones[byte * 8 + bit] += (value >> bit) & 1;
    }
  }
  Descriptor centre{};
  const int n = static_cast<int>(members.size());
  for (int b = 0; b < 256; ++b) {
    if (2 * ones[b] > n) centre[b / 8] |= static_cast<uint8_t>(1u << (b % 8));
  }
  return centre;
}

// Index of the nearest centre (ties: the lower index).
int Nearest(const Descriptor& d, const std::vector<Descriptor>& centres) {
  int best = 0, best_distance = 1 << 30;
  for (size_t c = 0; c < centres.size(); ++c) {
    const int distance = Distance(d, centres[c]);
    if (distance < best_distance) {
      best_distance = distance;
      best = static_cast<int>(c);
    }
  }
  return best;
}

// k-means++ seeding: the first centre uniformly, each next one with probability proportional to
// the squared distance to the nearest centre so far. Stops early when every member coincides
// with a centre (fewer than k distinct descriptors).
std::vector<Descriptor> SeedCentres(const std::vector<Descriptor>& all,
                                    const std::vector<int>& members, int k, Rng& rng) {
  const int n = static_cast<int>(members.size());
  std::vector<Descriptor> centres{all[members[rng.UniformInt(0, n - 1)]]};
  std::vector<double> d2(n);
  for (int i = 0; i < n; ++i) d2[i] = std::pow(Distance(all[members[i]], centres[0]), 2.0);
  while (static_cast<int>(centres.size()) < k) {
    double sum = 0.0;
    for (double v : d2) sum += v;
    if (sum <= 0.0) break;
    const double r = rng.Uniform(0.0, sum);
    int pick = -1;
    double cumulative = 0.0;
    for (int i = 0; i < n; ++i) {
      if (d2[i] <= 0.0) continue;
      pick = i;  // the last candidate if rounding leaves r above the total
      cumulative += d2[i];
      if (cumulative > r) break;
    }
    centres.push_back(all[members[pick]]);
    for (int i = 0; i < n; ++i) {
      d2[i] = std::min(d2[i], std::pow(Distance(all[members[i]], centres.back()), 2.0));
    }
  }
  return centres;
}

// Splits `members` into at most k clusters (k-majority); empty clusters are dropped. With at most
// k members, each distinct descriptor becomes its own cluster.
std::vector<Cluster> KMajority(const std::vector<Descriptor>& all, const std::vector<int>& members,
                               int k, int max_iterations, Rng& rng) {
  std::vector<Cluster> clusters;
  if (static_cast<int>(members.size()) <= k) {
    for (int m : members) {
      auto same = std::find_if(clusters.begin(), clusters.end(),
                               [&](const Cluster& c) { return c.centre == all[m]; });
      if (same == clusters.end()) {
        clusters.push_back({all[m], {m}});
      } else {
        same->members.push_back(m);
      }
    }
    return clusters;
  }
  std::vector<Descriptor> centres = SeedCentres(all, members, k, rng);
  const int c = static_cast<int>(centres.size());
  std::vector<int> assignment(members.size());
  for (size_t i = 0; i < members.size(); ++i) assignment[i] = Nearest(all[members[i]], centres);
  std::vector<std::vector<int>> groups(c);
  auto group = [&] {
    for (auto& g : groups) g.clear();
    for (size_t i = 0; i < members.size(); ++i) groups[assignment[i]].push_back(members[i]);
  };
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    group();
    for (int j = 0; j < c; ++j) {
      if (!groups[j].empty()) centres[j] = Majority(all, groups[j]);
    }
    bool changed = false;
    for (size_t i = 0; i < members.size(); ++i) {
      const int nearest = Nearest(all[members[i]], centres);
      changed = changed || nearest != assignment[i];
      assignment[i] = nearest;
    }
    if (!changed) break;
  }
  group();
  for (int j = 0; j < c; ++j) {
    if (!groups[j].empty()) clusters.push_back({Majority(all, groups[j]), std::move(groups[j])});
  }
  return clusters;
}

}  // namespace

void Vocabulary::Train(const std::vector<cv::Mat>& per_image_descriptors,
                       const VocabularyOptions& options, Rng& rng,
                       const VocabularyProgressFn& progress) {
  std::string error;
  if (!options.Check(&error)) throw InputError("Vocabulary::Train: " + error);
  std::vector<Descriptor> all;
  std::vector<int> image_of;
  for (size_t i = 0; i < per_image_descriptors.size(); ++i) {
    const cv::Mat& d = per_image_descriptors[i];
    if (d.empty()) continue;
    if (d.type() != CV_8UC1 || d.cols != 32) {
      throw InputError("Vocabulary::Train: descriptors of image " + std::to_string(i) +
                       " must be CV_8UC1 with 32 columns");
    }
    for (int r = 0; r < d.rows; ++r) {
      Descriptor row;
      std::memcpy(row.data(), d.ptr<uint8_t>(r), 32);
      all.push_back(row);
      image_of.push_back(static_cast<int>(i));
    }
  }
  if (all.empty()) throw InputError("Vocabulary::Train: no descriptors to train on");

  k_ = options.k;
  levels_ = options.levels;
  training_images_ = static_cast<int>(per_image_descriptors.size());
  nodes_.assign(1, Node{});
  struct Pending {
    int node;
    std::vector<int> members;
  };
  std::vector<Pending> frontier(1);
  frontier[0].node = 0;
  for (size_t i = 0; i < all.size(); ++i) frontier[0].members.push_back(static_cast<int>(i));
  for (int level = 1; level <= levels_ && !frontier.empty(); ++level) {
    VocabularyProgress p{level, levels_, 0, frontier.size()};
    if (progress) progress(p);
    std::vector<Pending> next;
    for (Pending& parent : frontier) {
      std::vector<Cluster> clusters =
          KMajority(all, parent.members, k_, options.max_iterations, rng);
      parent.members = {};
      // A node whose descriptors are all alike stays a leaf (the root always gets a child).
      if (clusters.size() > 1 || parent.node == 0) {
        for (Cluster& cluster : clusters) {
          const int index = static_cast<int>(nodes_.size());
          Node child;
          child.parent = parent.node;
          child.descriptor = cluster.centre;
          nodes_.push_back(child);
          if (level < levels_ && cluster.members.size() > 1) {
            next.push_back({index, std::move(cluster.members)});
          }
        }
      }
      ++p.nodes_done;
      if (progress) progress(p);
    }
    frontier = std::move(next);
  }
  std::vector<bool> has_child(nodes_.size(), false);
  for (size_t i = 1; i < nodes_.size(); ++i) has_child[nodes_[i].parent] = true;
  for (size_t i = 0; i < nodes_.size(); ++i) nodes_[i].is_leaf = !has_child[i];
  IndexNodes();

  // idf(word) = log(N / n_w), n_w: training images with the word (as Transform finds it; a word
  // no training image reaches counts as one image).
  // Descriptors are in image order, so remembering each word's last image counts images once.
  std::vector<int> images_with_word(words_.size(), 0), last_image(words_.size(), -1);
  for (size_t i = 0; i < all.size(); ++i) {
    const int word = WordOf(all[i].data());
    if (last_image[word] == image_of[i]) continue;
    last_image[word] = image_of[i];
    ++images_with_word[word];
  }
  const double n = training_images_;
  for (size_t w = 0; w < words_.size(); ++w) {
    const double nw = std::max(1, images_with_word[w]);
    nodes_[words_[w]].idf = std::log(n / nw);
  }
  spdlog::debug("vocabulary: {} words, {} nodes from {} descriptors of {} images", words_.size(),
                nodes_.size(), all.size(), training_images_);
}

}  // namespace detslam
