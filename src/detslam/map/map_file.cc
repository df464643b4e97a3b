// Map file format (version 2: version 1 plus the map id of every keyframe, for the atlas's several
// maps), little-endian, every count a uint64:
//   "DSLMMAP\0", uint32 version;
//   camera: int32 width, height; float64 fx, fy, cx, cy, k1, k2, p1, p2, k3, bf;
//   pyramid: float64 scale factor, int32 levels; uint64 vocabulary checksum (0: none);
//   int64 next keyframe id, next map point id;
//   count, then per keyframe (ascending id): int64 id, frame index, stamp (ns), parent (-1: none);
//     int32 map id;
//     pose cam_from_world: float64 qw, qx, qy, qz, tx, ty, tz;
//     count, then per keypoint: float32 x, y, size, angle, response; int32 octave, class id;
//       float64 undistorted x, y; float32 depth, u_right; 32 descriptor bytes;
//     uint8 has labels, then one byte per keypoint if so;
//     count, then per bag-of-words entry: int32 word, float64 weight;
//     count, then per direct-index node: int32 node, count, int32 keypoint indices;
//     count, then per covisible keyframe: int64 id, int32 weight;
//   count, then per map point (ascending id): int64 id; float64 x, y, z; uint8 has descriptor,
//     32 bytes if so; float64 normal x, y, z, min distance, max distance; int64 reference keyframe,
//     first keyframe; int32 visible, found; count, then per observation: int64 keyframe, uint64
//     keypoint index;
//   uint64 FNV-1a 64 of every byte before it.
#include "detslam/map/map_file.h"

#include <cmath>
#include <cstring>

#include "detslam/core/atomic_file.h"
#include "detslam/core/binary_io.h"
#include "detslam/core/check.h"

namespace detslam {
namespace {

constexpr char kMagic[8] = {'D', 'S', 'L', 'M', 'M', 'A', 'P', '\0'};
constexpr size_t kChecksumBytes = 8;
constexpr size_t kDescriptorBytes = 32;
constexpr uint64_t kMaxFileBytes = uint64_t(16) << 30;
// Smallest encodings, to check counts against what is left of the file.
constexpr size_t kKeypointBytes = 5 * 4 + 2 * 4 + 2 * 8 + 2 * 4 + kDescriptorBytes;
constexpr size_t kKeyFrameMinBytes = 4 * 8 + 4 + 7 * 8 + 8 + 1 + 8 + 8 + 8;
constexpr size_t kLandmarkMinBytes = 8 + 3 * 8 + 1 + 5 * 8 + 2 * 8 + 2 * 4 + 8;

double ScaleFactorOf(const ScaleInfo& scale) {
  return scale.scale_factors.size() > 1 ? scale.scale_factors[1] : 1.0;
}

void PutCamera(ByteWriter* w, const PinholeCamera& c) {
  w->I32(c.width);
  w->I32(c.height);
  for (double v : {c.fx, c.fy, c.cx, c.cy, c.k1, c.k2, c.p1, c.p2, c.k3, c.bf}) w->F64(v);
}

PinholeCamera GetCamera(ByteReader* r) {
  PinholeCamera c;
  c.width = r->I32("camera width");
  c.height = r->I32("camera height");
  for (double* v : {&c.fx, &c.fy, &c.cx, &c.cy, &c.k1, &c.k2, &c.p1, &c.p2, &c.k3, &c.bf})
    *v = r->F64("camera parameters");
  // The keyframes' keypoint grids span the undistorted image: a camera whose size, focal lengths
  // or distortion leave no finite, non-empty such area cannot have made this map (a size <= 0, a
  // zero or non-finite focal length all show up here).
  const ImageBounds b = UndistortedBounds(c);
  const double w = b.max_x - b.min_x, h = b.max_y - b.min_y;
  if (!(w > 0 && h > 0 && std::isfinite(w) && std::isfinite(h)))
    r->Fail("camera: invalid size, focal length or distortion (no undistorted image area)");
  return c;
}

void PutPose(ByteWriter* w, const Rigid3d& pose) {
  const Eigen::Quaterniond& q = pose.rotation();
  for (double v : {q.w(), q.x(), q.y(), q.z()}) w->F64(v);
  for (int i = 0; i < 3; ++i) w->F64(pose.translation()[i]);
}

Rigid3d GetPose(ByteReader* r, const std::string& where) {
  double v[7];
  for (double& x : v) x = r->F64("pose");
  for (double x : v) {
    if (!std::isfinite(x)) r->Fail(where + ": pose is not finite");
  }
  const Eigen::Quaterniond q(v[0], v[1], v[2], v[3]);
  if (std::abs(q.norm() - 1.0) > 1e-6) r->Fail(where + ": pose rotation is not a unit quaternion");
  return Rigid3d::FromUnitQuaternion(q, Eigen::Vector3d(v[4], v[5], v[6]));
}

Eigen::Vector3d GetVector3(ByteReader* r, const char* field, const std::string& where) {
  Eigen::Vector3d p;
  for (int i = 0; i < 3; ++i) p[i] = r->F64(field);
  if (!p.allFinite()) r->Fail(where + ": " + field + " is not finite");
  return p;
}

struct Header {
  MapFileInfo info;
  int64_t next_keyframe = 0, next_landmark = 0;
};

// Checks size, magic, checksum and version; reads the header fields.
Header ReadHeader(const std::string& bytes, ByteReader* r) {
  if (bytes.size() < sizeof(kMagic) + 4 + kChecksumBytes) {
    r->Fail("truncated (" + std::to_string(bytes.size()) + " bytes)");
  }
  if (std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0) r->Fail("not a detslam map file (wrong magic)");
  const size_t body = bytes.size() - kChecksumBytes;
  if (GetLE(bytes, body, 8) != Fnv1a64(bytes.data(), body)) r->Fail("checksum mismatch (corrupt or truncated)");
  char magic[sizeof(kMagic)];
  r->Raw(magic, sizeof(magic), "magic");
  Header h;
  h.info.bytes = bytes.size();
  h.info.version = r->U32("version");
  if (h.info.version != kMapFileVersion) {
    r->Fail("format version " + std::to_string(h.info.version) + ", this build reads version " +
            std::to_string(kMapFileVersion));
  }
  h.info.camera = GetCamera(r);
  h.info.scale_factor = r->F64("scale factor");
  h.info.levels = r->I32("levels");
  if (!(h.info.scale_factor >= 1.0) || h.info.levels < 1 || h.info.levels > 64)
    r->Fail("invalid pyramid (scale factor " + std::to_string(h.info.scale_factor) + ", " +
            std::to_string(h.info.levels) + " levels)");
  h.info.vocabulary_checksum = r->U64("vocabulary checksum");
  h.next_keyframe = r->I64("next keyframe id");
  h.next_landmark = r->I64("next map point id");
  if (h.next_keyframe < 0 || h.next_landmark < 0 || h.next_keyframe > (int64_t(1) << 62) ||
      h.next_landmark > (int64_t(1) << 62))
    r->Fail("invalid next ids");
  return h;
}

std::string Describe(const PinholeCamera& c) {
  char buf[200];
  std::snprintf(buf, sizeof(buf), "%dx%d fx %.3f fy %.3f cx %.3f cy %.3f bf %.3f", c.width,
                c.height, c.fx, c.fy, c.cx, c.cy, c.bf);
  return buf;
}

bool SameCamera(const PinholeCamera& a, const PinholeCamera& b) {
  auto near = [](double x, double y) { return std::abs(x - y) <= 1e-9 * std::max(1.0, std::abs(x)); };
  return a.width == b.width && a.height == b.height && near(a.fx, b.fx) && near(a.fy, b.fy) &&
         near(a.cx, b.cx) && near(a.cy, b.cy) && near(a.k1, b.k1) && near(a.k2, b.k2) &&
         near(a.p1, b.p1) && near(a.p2, b.p2) && near(a.k3, b.k3) && near(a.bf, b.bf);
}

KeyFrame GetKeyFrame(ByteReader* r, const PinholeCamera& camera, int levels) {
  KeyFrame kf;
  kf.id = r->I64("keyframe id");
  const std::string where = "keyframe " + std::to_string(kf.id);
  kf.frame_index = r->I64("frame index");
  kf.stamp = Timestamp{r->I64("stamp")};
  kf.parent = r->I64("parent");
  kf.map_id = r->I32("map id");
  kf.cam_from_world = GetPose(r, where);
  auto f = std::make_shared<FrameFeatures>();
  const uint64_t n = r->Count("keypoint count", kKeypointBytes);
  f->keypoints.resize(n);
  f->undist.resize(n);
  f->depth.resize(n);
  f->u_right.resize(n);
  f->descriptors = cv::Mat(static_cast<int>(n), static_cast<int>(kDescriptorBytes), CV_8UC1);
  for (uint64_t i = 0; i < n; ++i) {
    cv::KeyPoint& k = f->keypoints[i];
    k.pt.x = r->F32("keypoint");
    k.pt.y = r->F32("keypoint");
    k.size = r->F32("keypoint");
    k.angle = r->F32("keypoint");
    k.response = r->F32("keypoint");
    k.octave = r->I32("keypoint octave");
    k.class_id = r->I32("keypoint class");
    if (k.octave < 0 || k.octave >= levels)
      r->Fail(where + ": keypoint " + std::to_string(i) + " octave " + std::to_string(k.octave) +
              " outside the pyramid");
    f->undist[i].x() = r->F64("keypoint");
    f->undist[i].y() = r->F64("keypoint");
    f->depth[i] = r->F32("keypoint depth");
    f->u_right[i] = r->F32("keypoint u_right");
    if (!f->undist[i].allFinite() || !std::isfinite(k.pt.x) || !std::isfinite(k.pt.y) ||
        !std::isfinite(f->depth[i]) || !std::isfinite(f->u_right[i]))
      r->Fail(where + ": keypoint " + std::to_string(i) + " is not finite");
    r->Raw(f->descriptors.ptr<uint8_t>(static_cast<int>(i)), kDescriptorBytes, "descriptor");
  }
  const uint8_t has_labels = r->U8("labels flag");
  if (has_labels > 1) r->Fail(where + ": labels flag " + std::to_string(has_labels));
  if (has_labels) {
    kf.labels.resize(n);
    for (uint64_t i = 0; i < n; ++i) {
      const uint8_t l = r->U8("label");
      if (l > static_cast<uint8_t>(KeypointLabel::kGeometric))
        r->Fail(where + ": keypoint label " + std::to_string(l));
      kf.labels[i] = static_cast<KeypointLabel>(l);
    }
  }
  const uint64_t words = r->Count("bag-of-words count", 12);
  for (uint64_t i = 0; i < words; ++i) {
    const int word = r->I32("word");
    const double weight = r->F64("word weight");
    if (word < 0 || !std::isfinite(weight) || !f->bow.emplace(word, weight).second)
      r->Fail(where + ": bag-of-words entry " + std::to_string(i) + " is invalid or repeated");
  }
  const uint64_t nodes = r->Count("direct index count", 12);
  for (uint64_t i = 0; i < nodes; ++i) {
    const int node = r->I32("node");
    const uint64_t m = r->Count("direct index entries", 4);
    std::vector<int> idx(m);
    for (uint64_t j = 0; j < m; ++j) {
      idx[j] = r->I32("direct index entry");
      if (idx[j] < 0 || static_cast<uint64_t>(idx[j]) >= n)
        r->Fail(where + ": direct index refers to keypoint " + std::to_string(idx[j]));
    }
    if (node < 0 || !f->bow_nodes.emplace(node, std::move(idx)).second)
      r->Fail(where + ": direct index node " + std::to_string(node) + " is invalid or repeated");
  }
  const uint64_t covis = r->Count("covisibility count", 12);
  for (uint64_t i = 0; i < covis; ++i) {
    const KeyFrameId other = r->I64("covisible keyframe");
    const int weight = r->I32("covisibility weight");
    if (!kf.covisibility.emplace(other, weight).second)
      r->Fail(where + ": covisible keyframe " + std::to_string(other) + " repeated");
  }
  f->grid = MakeKeypointGrid(camera, f->keypoints, f->undist);
  kf.features = std::move(f);
  return kf;
}

Landmark GetLandmark(ByteReader* r) {
  Landmark lm;
  lm.id = r->I64("map point id");
  const std::string where = "map point " + std::to_string(lm.id);
  lm.position = GetVector3(r, "position", where);
  const uint8_t has_descriptor = r->U8("descriptor flag");
  if (has_descriptor > 1) r->Fail(where + ": descriptor flag " + std::to_string(has_descriptor));
  if (has_descriptor) {
    lm.descriptor = cv::Mat(1, static_cast<int>(kDescriptorBytes), CV_8UC1);
    r->Raw(lm.descriptor.data, kDescriptorBytes, "descriptor");
  }
  lm.normal = GetVector3(r, "normal", where);
  lm.min_distance = r->F64("min distance");
  lm.max_distance = r->F64("max distance");
  if (!std::isfinite(lm.min_distance) || !std::isfinite(lm.max_distance))
    r->Fail(where + ": distance bounds are not finite");
  lm.reference_keyframe = r->I64("reference keyframe");
  lm.first_keyframe = r->I64("first keyframe");
  lm.visible = r->I32("visible");
  lm.found = r->I32("found");
  const uint64_t obs = r->Count("observation count", 16);
  for (uint64_t i = 0; i < obs; ++i) {
    const KeyFrameId kf = r->I64("observation keyframe");
    const uint64_t idx = r->U64("observation keypoint");
    if (!lm.observations.emplace(kf, static_cast<size_t>(idx)).second)
      r->Fail(where + ": keyframe " + std::to_string(kf) + " observes it twice");
  }
  return lm;
}

}  // namespace

std::string EncodeMapFile(const Map& map, const PinholeCamera& camera,
                          uint64_t vocabulary_checksum) {
  ByteWriter w;
  w.Raw(kMagic, sizeof(kMagic));
  w.U32(kMapFileVersion);
  PutCamera(&w, camera);
  w.F64(ScaleFactorOf(map.scale()));
  w.I32(map.scale().num_levels());
  w.U64(vocabulary_checksum);
  w.I64(map.next_keyframe_id());
  w.I64(map.next_landmark_id());
  w.U64(map.NumKeyFrames());
  for (const auto& [id, kf] : map.keyframes()) {
    w.I64(id);
    w.I64(kf.frame_index);
    w.I64(kf.stamp.ns);
    w.I64(kf.parent);
    w.I32(kf.map_id);
    PutPose(&w, kf.cam_from_world);
    const FrameFeatures& f = *kf.features;
    w.U64(f.size());
    for (size_t i = 0; i < f.size(); ++i) {
      const cv::KeyPoint& k = f.keypoints[i];
      for (float v : {k.pt.x, k.pt.y, k.size, k.angle, k.response}) w.F32(v);
      w.I32(k.octave);
      w.I32(k.class_id);
      w.F64(f.undist[i].x());
      w.F64(f.undist[i].y());
      w.F32(f.depth[i]);
      w.F32(f.u_right[i]);
      w.Raw(f.Descriptor(i), kDescriptorBytes);
    }
    w.U8(kf.labels.empty() ? 0 : 1);
    for (KeypointLabel l : kf.labels) w.U8(static_cast<uint8_t>(l));
    w.U64(f.bow.size());
    for (const auto& [word, weight] : f.bow) {
      w.I32(word);
      w.F64(weight);
    }
    w.U64(f.bow_nodes.size());
    for (const auto& [node, idx] : f.bow_nodes) {
      w.I32(node);
      w.U64(idx.size());
      for (int i : idx) w.I32(i);
    }
    w.U64(kf.covisibility.size());
    for (const auto& [other, weight] : kf.covisibility) {
      w.I64(other);
      w.I32(weight);
    }
  }
  w.U64(map.NumLandmarks());
  for (const auto& [id, lm] : map.landmarks()) {
    w.I64(id);
    for (int i = 0; i < 3; ++i) w.F64(lm.position[i]);
    const bool has_descriptor = lm.descriptor.total() == kDescriptorBytes;
    w.U8(has_descriptor ? 1 : 0);
    if (has_descriptor) w.Raw(lm.descriptor.data, kDescriptorBytes);
    for (int i = 0; i < 3; ++i) w.F64(lm.normal[i]);
    w.F64(lm.min_distance);
    w.F64(lm.max_distance);
    w.I64(lm.reference_keyframe);
    w.I64(lm.first_keyframe);
    w.I32(lm.visible);
    w.I32(lm.found);
    w.U64(lm.observations.size());
    for (const auto& [kf, idx] : lm.observations) {
      w.I64(kf);
      w.U64(idx);
    }
  }
  return w.Finish();
}

void SaveMapFile(const std::string& path, const Map& map, const PinholeCamera& camera,
                 uint64_t vocabulary_checksum) {
  WriteBytesAtomically(path, EncodeMapFile(map, camera, vocabulary_checksum));
}

namespace {

// Parses the keyframes and map points after the header; grids from `camera`.
Map ParseBody(ByteReader* r, Header* h, const PinholeCamera& camera) {
  std::vector<KeyFrame> keyframes(r->Count("keyframe count", kKeyFrameMinBytes));
  for (KeyFrame& kf : keyframes) kf = GetKeyFrame(r, camera, h->info.levels);
  std::vector<Landmark> landmarks(r->Count("map point count", kLandmarkMinBytes));
  for (Landmark& lm : landmarks) lm = GetLandmark(r);
  if (r->remaining() != kChecksumBytes) {
    r->Fail(std::to_string(r->remaining() - kChecksumBytes) +
            " unexpected bytes before the checksum");
  }
  h->info.keyframes = keyframes.size();
  h->info.landmarks = landmarks.size();
  try {
    return Map::Restore(ScaleInfo::Geometric(h->info.scale_factor, h->info.levels),
                        std::move(keyframes), std::move(landmarks), h->next_keyframe,
                        h->next_landmark);
  } catch (const InputError& e) {
    r->Fail(e.what());
  }
}

}  // namespace

MapFileInfo ReadMapFileInfo(const std::string& path) {
  const std::string bytes = ReadFileBytes(path, kMaxFileBytes, "map file");
  ByteReader r(bytes, path, "map file");
  Header h = ReadHeader(bytes, &r);
  ParseBody(&r, &h, h.info.camera);
  return h.info;
}

Map LoadMapFile(const std::string& path, const MapFileExpectation& expected, MapFileInfo* info) {
  const std::string bytes = ReadFileBytes(path, kMaxFileBytes, "map file");
  ByteReader r(bytes, path, "map file");
  Header h = ReadHeader(bytes, &r);
  if (!SameCamera(h.info.camera, expected.camera)) {
    r.Fail("made with another camera (" + Describe(h.info.camera) + "; this run: " +
           Describe(expected.camera) + ")");
  }
  if (h.info.levels != expected.scale.num_levels() ||
      std::abs(h.info.scale_factor - ScaleFactorOf(expected.scale)) > 1e-12) {
    r.Fail("made with another ORB pyramid (" + std::to_string(h.info.levels) + " levels, factor " +
           std::to_string(h.info.scale_factor) + "; this run: " +
           std::to_string(expected.scale.num_levels()) + " levels, factor " +
           std::to_string(ScaleFactorOf(expected.scale)) + ")");
  }
  if (h.info.vocabulary_checksum != expected.vocabulary_checksum) {
    r.Fail(h.info.vocabulary_checksum == 0 || expected.vocabulary_checksum == 0
               ? std::string("made ") + (h.info.vocabulary_checksum ? "with" : "without") +
                     " a vocabulary, this run has " +
                     (expected.vocabulary_checksum ? "one" : "none")
               : "made with another vocabulary (its checksum differs from this run's)");
  }
  Map map = ParseBody(&r, &h, expected.camera);
  if (info) *info = h.info;
  return map;
}

}  // namespace detslam
