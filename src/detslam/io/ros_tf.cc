#include "detslam/io/ros_tf.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "detslam/core/check.h"
#include "detslam/io/rosbag_file.h"

namespace detslam {
namespace {

std::string Normalize(const std::string& frame) {
  return !frame.empty() && frame[0] == '/' ? frame.substr(1) : frame;
}

Rigid3d ToRigid(const RosTransform& t) {
  const Eigen::Quaterniond q(t.rotation[3], t.rotation[0], t.rotation[1], t.rotation[2]);
  return Rigid3d(q, Eigen::Vector3d(t.translation[0], t.translation[1], t.translation[2]));
}

bool SamePose(const Rigid3d& a, const Rigid3d& b) {
  return a.translation() == b.translation() && a.rotation().coeffs() == b.rotation().coeffs();
}

std::string Join(const std::vector<std::string>& v) {
  std::string s;
  for (const std::string& x : v) s += (s.empty() ? "" : ", ") + x;
  return s.empty() ? "none" : s;
}

}  // namespace

void TfBuffer::Add(const RosTransform& t) {
  const std::string child = Normalize(t.child_frame_id), parent = Normalize(t.header.frame_id);
  if (child.empty() || parent.empty() || child == parent) {
    ++ignored_;
    return;
  }
  const bool finite = std::all_of(t.translation.begin(), t.translation.end(),
                                  [](double v) { return std::isfinite(v); }) &&
                      std::all_of(t.rotation.begin(), t.rotation.end(),
                                  [](double v) { return std::isfinite(v); });
  const double norm = std::sqrt(t.rotation[0] * t.rotation[0] + t.rotation[1] * t.rotation[1] +
                                t.rotation[2] * t.rotation[2] + t.rotation[3] * t.rotation[3]);
  if (!finite || !(norm > 1e-9)) {
    ++ignored_;
    return;
  }
  Edge& e = by_child_[child];
  if (e.parent.empty()) e.parent = parent;
  if (e.parent != parent) {
    ++ignored_;
    return;
  }
  const Rigid3d pose = ToRigid(t);
  if (!e.samples.empty() && !SamePose(e.samples.front().second, pose)) e.fixed = false;
  e.samples.emplace_back(t.header.stamp, pose);
}

void TfBuffer::Finish() {
  for (auto& [child, e] : by_child_) {
    std::stable_sort(e.samples.begin(), e.samples.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    e.samples.erase(std::unique(e.samples.begin(), e.samples.end(),
                                [](const auto& a, const auto& b) { return a.first == b.first; }),
                    e.samples.end());
  }
}

bool TfBuffer::Has(const std::string& frame) const {
  const std::string f = Normalize(frame);
  if (by_child_.count(f)) return true;
  for (const auto& [child, e] : by_child_) {
    if (e.parent == f) return true;
  }
  return false;
}

std::vector<std::string> TfBuffer::Frames() const {
  std::set<std::string> frames;
  for (const auto& [child, e] : by_child_) {
    frames.insert(child);
    frames.insert(e.parent);
  }
  return {frames.begin(), frames.end()};
}

std::vector<std::string> TfBuffer::Ancestors(const std::string& frame) const {
  std::vector<std::string> chain = {frame};
  std::set<std::string> seen = {frame};
  for (auto it = by_child_.find(frame); it != by_child_.end(); it = by_child_.find(chain.back())) {
    if (!seen.insert(it->second.parent).second) break;  // a cycle: stop at the repeat
    chain.push_back(it->second.parent);
  }
  return chain;
}

bool TfBuffer::Chains(const std::string& parent, const std::string& child,
                      std::vector<std::string>* up_parent, std::vector<std::string>* up_child) const {
  const std::vector<std::string> a = Ancestors(Normalize(parent)), b = Ancestors(Normalize(child));
  const std::set<std::string> in_a(a.begin(), a.end());
  for (size_t j = 0; j < b.size(); ++j) {
    if (!in_a.count(b[j])) continue;
    up_child->assign(b.begin(), b.begin() + static_cast<long>(j));
    up_parent->assign(a.begin(), std::find(a.begin(), a.end(), b[j]));
    return true;
  }
  return false;
}

std::optional<Rigid3d> TfBuffer::EdgeAt(const Edge& e, Timestamp t, double max_gap_s) const {
  if (e.samples.empty()) return std::nullopt;
  if (e.fixed) return e.samples.front().second;
  const auto after = std::lower_bound(e.samples.begin(), e.samples.end(), t,
                                      [](const auto& s, Timestamp x) { return s.first < x; });
  if (after != e.samples.end() && after->first == t) return after->second;
  if (after == e.samples.begin() || after == e.samples.end()) return std::nullopt;
  const auto before = after - 1;
  const double gap = AbsDiffSeconds(after->first, before->first);
  if (gap > max_gap_s) return std::nullopt;
  const double w = AbsDiffSeconds(t, before->first) / gap;
  const Rigid3d& a = before->second;
  const Rigid3d& b = after->second;
  return Rigid3d(a.rotation().slerp(w, b.rotation()),
                 (1 - w) * a.translation() + w * b.translation());
}

std::optional<Rigid3d> TfBuffer::Lookup(const std::string& parent, const std::string& child,
                                        Timestamp t, double max_gap_s) const {
  std::vector<std::string> up_parent, up_child;
  if (!Chains(parent, child, &up_parent, &up_child)) return std::nullopt;
  const auto up = [&](const std::vector<std::string>& edges) -> std::optional<Rigid3d> {
    Rigid3d top_from_frame;  // identity
    for (const std::string& c : edges) {
      const std::optional<Rigid3d> e = EdgeAt(by_child_.at(c), t, max_gap_s);
      if (!e) return std::nullopt;
      top_from_frame = *e * top_from_frame;
    }
    return top_from_frame;
  };
  const std::optional<Rigid3d> top_from_child = up(up_child), top_from_parent = up(up_parent);
  if (!top_from_child || !top_from_parent) return std::nullopt;
  return top_from_parent->Inverse() * *top_from_child;
}

std::vector<Timestamp> TfBuffer::ChainStamps(const std::string& parent,
                                             const std::string& child) const {
  std::vector<std::string> up_parent, up_child;
  if (!Chains(parent, child, &up_parent, &up_child)) return {};
  const Edge* busiest = nullptr;
  for (const auto* edges : {&up_parent, &up_child}) {
    for (const std::string& c : *edges) {
      const Edge& e = by_child_.at(c);
      if (!e.fixed && (!busiest || e.samples.size() > busiest->samples.size())) busiest = &e;
    }
  }
  std::vector<Timestamp> stamps;
  if (busiest) {
    for (const auto& s : busiest->samples) stamps.push_back(s.first);
  }
  return stamps;
}

bool TfGroundTruthOptions::Check(std::string* error) const {
  std::string e;
  if (Normalize(parent).empty()) e += "parent frame must not be empty; ";
  if (tf_topics.empty()) e += "tf_topics must not be empty; ";
  if (!(max_gap_s > 0)) e += "max_gap_s must be positive; ";
  if (error != nullptr) *error = e;
  return e.empty();
}

TfGroundTruth GroundTruthFromBag(const std::string& bag_path, const TfGroundTruthOptions& options) {
  std::string error;
  if (!options.Check(&error)) throw InputError(bag_path, 0, "invalid ground-truth options: " + error);
  TfBuffer tf;
  TfGroundTruth out;
  std::string image_frame, parse_error;
  RosbagFile::Open(bag_path, [&](const RosbagMessage& m, const RosbagConnection& c,
                                 const uint8_t* data) {
    if (!parse_error.empty()) return;
    try {
      if (std::find(options.tf_topics.begin(), options.tf_topics.end(), c.topic) !=
              options.tf_topics.end() &&
          (c.type == "tf2_msgs/TFMessage" || c.type == "tf/tfMessage")) {
        for (const RosTransform& t : ParseRosTfMessage(data, m.size)) {
          tf.Add(t);
          ++out.transforms;
        }
      } else if (options.child.empty() && image_frame.empty() && c.topic == options.rgb_topic &&
                 c.type == "sensor_msgs/Image") {
        image_frame = ParseRosImage(data, m.size).header.frame_id;
      }
    } catch (const std::exception& e) {
      parse_error = "topic " + c.topic + " (received " + m.record_time.ToString() + "): " + e.what();
    }
  });
  if (!parse_error.empty()) throw InputError(bag_path, 0, parse_error);
  tf.Finish();
  if (out.transforms == 0) {
    throw InputError(bag_path, 0, "no tf transforms on " + Join(options.tf_topics));
  }
  out.parent = Normalize(options.parent);
  out.child = Normalize(options.child.empty() ? image_frame : options.child);
  if (out.child.empty()) {
    throw InputError(bag_path, 0,
                     "no camera frame: name it (the child frame), or record " + options.rgb_topic +
                         " with a header frame_id");
  }
  for (const std::string& f : {out.parent, out.child}) {
    if (!tf.Has(f)) {
      throw InputError(bag_path, 0, "frame '" + f + "' is not in the tf tree (frames: " +
                                        Join(tf.Frames()) + ")");
    }
  }
  const std::vector<Timestamp> stamps = tf.ChainStamps(out.parent, out.child);
  if (stamps.empty()) {
    throw InputError(bag_path, 0,
                     "no moving transform connects '" + out.parent + "' and '" + out.child +
                         "' (frames: " + Join(tf.Frames()) + ")");
  }
  for (Timestamp t : stamps) {
    const std::optional<Rigid3d> pose = tf.Lookup(out.parent, out.child, t, options.max_gap_s);
    if (pose) out.trajectory.push_back({t, *pose});
  }
  if (tf.ignored() > 0) {
    spdlog::warn("{}: {} tf transforms ignored (a second parent for a frame, a self-loop, or "
                 "non-finite values)",
                 bag_path, tf.ignored());
  }
  return out;
}

}  // namespace detslam
