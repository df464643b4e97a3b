// Vocabulary file format (version 1), little-endian, fixed-width:
//   "DSLMVOC\0" (8 bytes), uint32 version (1), uint32 k, uint32 levels, uint32 training images,
//   uint32 node count; then per node in index order (node 0 is the root, every parent precedes its
//   children): int32 parent (-1 for the root), uint8 is_leaf, int32 word id (-1 for inner nodes),
//   float64 idf, 32 bytes descriptor; then uint64 FNV-1a 64 over every byte before it.
#include <cmath>
#include <cstring>

#include "detslam/core/atomic_file.h"
#include "detslam/core/binary_io.h"
#include "detslam/core/check.h"
#include "detslam/place/vocabulary.h"

namespace detslam {
namespace {

constexpr char kMagic[8] = {'D', 'S', 'L', 'M', 'V', 'O', 'C', '\0'};
constexpr size_t kHeaderBytes = 8 + 5 * 4;
constexpr size_t kNodeBytes = 4 + 1 + 4 + 8 + 32;
constexpr size_t kChecksumBytes = 8;

std::string Encode(const Vocabulary& v) {
  std::string out(kMagic, sizeof(kMagic));
  PutLE(&out, Vocabulary::kFormatVersion, 4);
  PutLE(&out, static_cast<uint32_t>(v.k()), 4);
  PutLE(&out, static_cast<uint32_t>(v.levels()), 4);
  PutLE(&out, static_cast<uint32_t>(v.training_images()), 4);
  PutLE(&out, static_cast<uint32_t>(v.num_nodes()), 4);
  for (const Vocabulary::Node& node : v.nodes()) {
    PutLE(&out, static_cast<uint32_t>(node.parent), 4);
    PutLE(&out, node.is_leaf ? 1 : 0, 1);
    PutLE(&out, static_cast<uint32_t>(node.word_id), 4);
    uint64_t idf_bits;
    std::memcpy(&idf_bits, &node.idf, 8);
    PutLE(&out, idf_bits, 8);
    out.append(reinterpret_cast<const char*>(node.descriptor.data()), 32);
  }
  PutLE(&out, Fnv1a64(out.data(), out.size()), 8);
  return out;
}

}  // namespace

void Vocabulary::Save(const std::string& path) const {
  DETSLAM_CHECK_MSG(!nodes_.empty(), "saving an empty vocabulary");
  WriteBytesAtomically(path, Encode(*this));
}

uint64_t Vocabulary::Checksum() const {
  const std::string bytes = Encode(*this);
  return GetLE(bytes, bytes.size() - kChecksumBytes, 8);
}

void Vocabulary::Load(const std::string& path) {
  auto fail = [&path](const std::string& what) {
    throw InputError(path, 0, "vocabulary file: " + what);
  };
  const std::string bytes = ReadFileBytes(path, uint64_t(1) << 32, "vocabulary file");
  if (bytes.size() < kHeaderBytes + kChecksumBytes) {
    fail("truncated (" + std::to_string(bytes.size()) + " bytes, a header needs " +
         std::to_string(kHeaderBytes + kChecksumBytes) + ")");
  }
  if (std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0) {
    fail("not a detslam vocabulary (wrong magic)");
  }
  const uint64_t version = GetLE(bytes, 8, 4);
  if (version != kFormatVersion) {
    fail("format version " + std::to_string(version) + ", this build reads version " +
         std::to_string(kFormatVersion));
  }
  const uint64_t k = GetLE(bytes, 12, 4), levels = GetLE(bytes, 16, 4);
  const uint64_t training_images = GetLE(bytes, 20, 4), node_count = GetLE(bytes, 24, 4);
  const uint64_t expected = kHeaderBytes + node_count * kNodeBytes + kChecksumBytes;
  if (bytes.size() != expected) {
    fail("length " + std::to_string(bytes.size()) + " bytes does not match its node count " +
         std::to_string(node_count) + " (expected " + std::to_string(expected) +
         " bytes; truncated or corrupt)");
  }
  const size_t body = bytes.size() - kChecksumBytes;
  if (GetLE(bytes, body, 8) != Fnv1a64(bytes.data(), body)) fail("checksum mismatch (corrupt)");
  VocabularyOptions options;
  options.k = static_cast<int>(std::min<uint64_t>(k, 1u << 30));
  options.levels = static_cast<int>(std::min<uint64_t>(levels, 1u << 30));
  std::string error;
  if (!options.Check(&error)) fail(error);
  if (node_count < 2) fail("needs a root and at least one word");
  if (training_images > (1u << 30)) fail("absurd training image count");

  std::vector<Node> nodes(node_count);
  std::vector<int> depth(node_count, 0), children(node_count, 0);
  size_t words = 0;
  for (size_t i = 0; i < node_count; ++i) {
    const size_t at = kHeaderBytes + i * kNodeBytes;
    Node& node = nodes[i];
    const std::string where = "node " + std::to_string(i) + ": ";
    node.parent = static_cast<int32_t>(GetLE(bytes, at, 4));
    const uint64_t leaf = GetLE(bytes, at + 4, 1);
    node.word_id = static_cast<int32_t>(GetLE(bytes, at + 5, 4));
    const uint64_t idf_bits = GetLE(bytes, at + 9, 8);
    std::memcpy(&node.idf, &idf_bits, 8);
    std::memcpy(node.descriptor.data(), bytes.data() + at + 17, 32);
    if (leaf > 1) fail(where + "leaf flag " + std::to_string(leaf) + " is not 0 or 1");
    node.is_leaf = leaf == 1;
    if (i == 0) {
      if (node.parent != -1 || node.is_leaf)
        fail(where + "the root must have parent -1 and not be a leaf");
    } else {
      if (node.parent < 0 || static_cast<size_t>(node.parent) >= i) {
        fail(where + "parent " + std::to_string(node.parent) + " out of range [0, " +
             std::to_string(i) + ")");
      }
      if (nodes[node.parent].is_leaf)
        fail(where + "parent " + std::to_string(node.parent) + " is a leaf");
      depth[i] = depth[node.parent] + 1;
      if (depth[i] > static_cast<int>(levels)) fail(where + "deeper than the levels");
      if (++children[node.parent] > static_cast<int>(k)) {
        fail(where + "parent " + std::to_string(node.parent) + " has more than k children");
      }
    }
    if (node.is_leaf) {
      if (node.word_id != static_cast<int>(words)) {
        fail(where + "word id " + std::to_string(node.word_id) + ", expected " +
             std::to_string(words));
      }
      if (!std::isfinite(node.idf) || node.idf < 0.0) fail(where + "idf is not finite and >= 0");
      ++words;
    } else if (node.word_id != -1) {
      fail(where + "an inner node with word id " + std::to_string(node.word_id));
    }
  }
  for (size_t i = 0; i < node_count; ++i) {
    if (!nodes[i].is_leaf && children[i] == 0) {
      fail("node " + std::to_string(i) + ": an inner node without children");
    }
  }
  k_ = static_cast<int>(k);
  levels_ = static_cast<int>(levels);
  training_images_ = static_cast<int>(training_images);
  nodes_ = std::move(nodes);
  IndexNodes();
}

}  // namespace detslam
