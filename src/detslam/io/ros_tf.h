// Transforms from a bag's tf topics (/tf and /tf_static: tf2_msgs/TFMessage, or the older
// tf/tfMessage with the same wire format) and the trajectory of one frame in another: how a bag's
// motion-capture ground truth (TUM bags: /world -> /kinect at 100 Hz, then fixed transforms to
// the camera frames) becomes a TUM groundtruth.txt.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "detslam/core/rigid3d.h"
#include "detslam/io/ros_messages.h"
#include "detslam/io/trajectory.h"

namespace detslam {

// A tf tree: each frame has one parent and a time series of parent_from_child transforms.
class TfBuffer {
 public:
  // Adds one transform. Frame names are compared without a leading '/' (tf2's convention). A
  // transform that gives a frame a second parent is ignored (counted in ignored()).
  void Add(const RosTransform& t);
  // Sorts the samples; call after the last Add and before any lookup.
  void Finish();

  // parent_from_child at time t along the tree; nullopt when the frames are not connected, or a
  // moving edge of the chain has no samples around t (outside its span, or a gap longer than
  // max_gap_s between the two samples around t). An edge whose samples are all the same (a fixed
  // transform, e.g. on /tf_static) holds at every time. Moving edges are interpolated (linear
  // translation, slerp rotation).
  std::optional<Rigid3d> Lookup(const std::string& parent, const std::string& child, Timestamp t,
                                double max_gap_s = 0.1) const;
  // The stamps at which the chain between the two frames moves: the samples of its most often
  // published moving edge (empty when the frames are not connected or nothing on the chain moves).
  std::vector<Timestamp> ChainStamps(const std::string& parent, const std::string& child) const;
  bool Has(const std::string& frame) const;
  std::vector<std::string> Frames() const;  // every frame named, sorted
  size_t ignored() const { return ignored_; }

 private:
  struct Edge {
    std::string parent;
    std::vector<std::pair<Timestamp, Rigid3d>> samples;
    bool fixed = true;  // all samples equal
  };
  // Frames from `frame` up to its root, `frame` first.
  std::vector<std::string> Ancestors(const std::string& frame) const;
  // The common ancestor's chains: edges (child names) from each frame up to it.
  bool Chains(const std::string& parent, const std::string& child, std::vector<std::string>* up_parent,
              std::vector<std::string>* up_child) const;
  std::optional<Rigid3d> EdgeAt(const Edge& e, Timestamp t, double max_gap_s) const;

  std::map<std::string, Edge> by_child_;
  size_t ignored_ = 0;
};

struct TfGroundTruthOptions {
  std::string parent = "world";  // the fixed frame (TUM bags: /world, the motion-capture frame)
  std::string child;             // the camera frame; empty: the colour images' header frame_id
  std::string rgb_topic = "/camera/rgb/image_color";  // where an empty `child` is looked up
  std::vector<std::string> tf_topics = {"/tf", "/tf_static"};
  double max_gap_s = 0.1;  // longest gap between two samples of a moving edge to interpolate over

  bool Check(std::string* error) const;
};

struct TfGroundTruth {
  Trajectory trajectory;  // world_from_cam = parent_from_child, at the chain's stamps
  std::string parent, child;
  size_t transforms = 0;  // tf transforms read
};

// Reads the bag's tf topics and returns the trajectory of options.child in options.parent.
// Throws InputError naming the bag when it has no tf messages, a tf message does not parse, a
// frame is missing (the message lists the frames there are), or the frames are not connected.
TfGroundTruth GroundTruthFromBag(const std::string& bag_path, const TfGroundTruthOptions& options);

}  // namespace detslam
