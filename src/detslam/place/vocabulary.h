// Bag-of-words vocabulary tree over 256-bit ORB descriptors (after Galvez-Lopez and Tardos 2012,
// "Bags of Binary Words"): hierarchical k-medians ("k-majority") clustering with k-means++ seeding,
// Hamming distance, leaves are words weighted by tf-idf. Our own code and file format; it does not
// read DBoW2 / ORB-SLAM vocabularies (and our descriptors differ from theirs anyway).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "detslam/core/rng.h"
#include "detslam/place/bow_vector.h"

namespace detslam {

struct VocabularyOptions {
  int k = 10;               // branching factor: children per node
  int levels = 6;           // depth of the tree (root excluded); up to k^levels words
  int max_iterations = 10;  // k-majority iterations per node (stops early when assignments settle)

  bool Check(std::string* error) const;
};

// Training progress: called when a level starts (nodes_done = 0) and after each node of it.
struct VocabularyProgress {
  int level = 0;              // 1..levels
  int levels = 0;             // total levels
  size_t nodes_done = 0;      // nodes of this level clustered so far
  size_t nodes_at_level = 0;  // nodes of this level to cluster
};
using VocabularyProgressFn = std::function<void(const VocabularyProgress&)>;

class Vocabulary {
 public:
  using Descriptor = std::array<uint8_t, 32>;

  struct Node {
    int parent = -1;            // index of the parent node; -1 for the root (node 0)
    bool is_leaf = false;       // leaves are words
    int word_id = -1;           // 0..size()-1 for a leaf, -1 otherwise
    double idf = 0.0;           // log(N / n_w) for a leaf, 0 otherwise
    Descriptor descriptor{};    // cluster centre (per-bit majority); zeros for the root
    std::vector<int> children;  // child node indices, ascending (not stored in the file)
  };

  static constexpr uint32_t kFormatVersion = 1;

  // Trains the tree on the ORB descriptors of N images (CV_8UC1, n x 32 each; empty images count
  // towards N). Deterministic for a given Rng state. Throws InputError on bad options or
  // descriptors of the wrong type, or when there is no descriptor at all.
  void Train(const std::vector<cv::Mat>& per_image_descriptors, const VocabularyOptions& options,
             Rng& rng, const VocabularyProgressFn& progress = nullptr);

  // Words of the descriptors (CV_8UC1, n x 32) as a tf-idf BowVector (L1-normalised). With
  // `features`, also the direct index at `levels_up` levels above the leaves: each descriptor is
  // listed under its path's node at depth levels - levels_up (the leaf itself where the leaf is
  // shallower; the root for levels_up >= levels). Throws InputError on a wrong descriptor type;
  // CHECKs that the vocabulary is not empty.
  BowVector Transform(const cv::Mat& descriptors, FeatureVector* features = nullptr,
                      int levels_up = 0) const;

  // Word id of one 32-byte descriptor, and optionally its path's node at depth `depth`.
  int WordOf(const uint8_t* descriptor, int depth = 0, int* node_at_depth = nullptr) const;

  static double Score(const BowVector& a, const BowVector& b) { return ScoreL1(a, b); }

  // Writes the binary format (see vocabulary_io.cc) atomically; throws InputError on failure.
  void Save(const std::string& path) const;
  // Reads and validates a file written by Save; throws InputError naming the file and the fault
  // (missing, truncated, corrupt, other version). Leaves *this unchanged on error.
  void Load(const std::string& path);
  // FNV-1a 64 of the file Save writes (identifies the vocabulary, e.g. in a map file).
  uint64_t Checksum() const;

  bool empty() const { return words_.empty(); }
  size_t size() const { return words_.size(); }  // number of words
  size_t num_nodes() const { return nodes_.size(); }
  int k() const { return k_; }
  int levels() const { return levels_; }
  int training_images() const { return training_images_; }
  const std::vector<Node>& nodes() const { return nodes_; }
  // Node index of each word.
  const std::vector<int>& word_nodes() const { return words_; }
  double WordIdf(int word_id) const { return nodes_[words_[word_id]].idf; }

 private:
  // Numbers leaves as words in node order and fills every node's children list.
  void IndexNodes();

  int k_ = 0;
  int levels_ = 0;
  int training_images_ = 0;
  std::vector<Node> nodes_;
  std::vector<int> words_;  // word id -> node index
};

}  // namespace detslam
