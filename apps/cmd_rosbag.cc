// `detslam rosbag info FILE`: what a ROS 1 bag holds (topics, types, message counts, chunks,
// whether it was closed properly). `detslam rosbag groundtruth FILE --out F`: the camera's
// trajectory from the bag's tf topics as a TUM groundtruth file for `detslam eval`.
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include "commands.h"
#include "detslam/core/check.h"
#include "detslam/io/ros_tf.h"
#include "detslam/io/rosbag_file.h"
#include "detslam/io/trajectory.h"

namespace detslam::app {
namespace {

void PrintBagInfo(const std::string& path) {
  const RosbagFile bag = RosbagFile::Open(path);
  std::map<uint32_t, size_t> counts;
  Timestamp first{INT64_MAX}, last{INT64_MIN};
  for (const RosbagMessage& m : bag.messages()) {
    ++counts[m.connection];
    if (m.record_time < first) first = m.record_time;
    if (last < m.record_time) last = m.record_time;
  }
  size_t by_compression[3] = {0, 0, 0};
  for (const RosbagChunk& c : bag.chunks()) ++by_compression[static_cast<int>(c.compression)];
  std::printf("%s: ROS bag format 2.0, %ju bytes, %s\n", path.c_str(),
              static_cast<uintmax_t>(std::filesystem::file_size(path)),
              bag.indexed() ? "indexed (closed by its recorder)" : "unindexed (not closed)");
  if (!bag.truncation().empty()) std::printf("cut off: %s\n", bag.truncation().c_str());
  std::printf("chunks: %zu (uncompressed %zu, bz2 %zu, lz4 %zu)\n", bag.chunks().size(),
              by_compression[0], by_compression[1], by_compression[2]);
  if (!bag.messages().empty()) {
    std::printf("messages: %zu, received from %s to %s (%.1f s)\n", bag.messages().size(),
                first.ToString().c_str(), last.ToString().c_str(),
                static_cast<double>(last.ns - first.ns) * 1e-9);
  } else {
    std::printf("messages: 0\n");
  }
  std::printf("topics:\n");
  for (const RosbagConnection& c : bag.connections()) {
    std::printf("  %-40s %8zu msgs  %s\n", c.topic.c_str(), counts[c.id], c.type.c_str());
  }
}

struct GroundTruthArgs {
  std::string bag, out;
  TfGroundTruthOptions options;
};

void WriteGroundTruth(const GroundTruthArgs& a) {
  const TfGroundTruth gt = GroundTruthFromBag(a.bag, a.options);
  if (gt.trajectory.empty()) {
    throw InputError(a.bag, 0,
                     "tf connects '" + gt.parent + "' and '" + gt.child +
                         "' but no pose could be composed (moving transforms never overlap in time "
                         "within --max-gap)");
  }
  WriteTumTrajectory(a.out, gt.trajectory,
                     "ground truth from the tf topics of " + a.bag + ": pose of frame '" +
                         gt.child + "' in frame '" + gt.parent + "' (world_from_camera)");
  const double span = static_cast<double>(gt.trajectory.back().stamp.ns -
                                          gt.trajectory.front().stamp.ns) * 1e-9;
  std::printf("%s: %zu poses of '%s' in '%s' over %.1f s (from %zu tf transforms)\n",
              a.out.c_str(), gt.trajectory.size(), gt.child.c_str(), gt.parent.c_str(), span,
              gt.transforms);
}

}  // namespace

void AddRosbagCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("rosbag", "Inspect ROS 1 bags; export their tf ground truth");
  cmd->require_subcommand(1);
  auto* info = cmd->add_subcommand("info", "Topics, types, message counts and chunks of a bag");
  auto file = std::make_shared<std::string>();
  info->add_option("file", *file, "ROS 1 bag")->required();
  info->callback([file] { PrintBagInfo(*file); });

  auto args = std::make_shared<GroundTruthArgs>();
  auto* gt = cmd->add_subcommand(
      "groundtruth", "Write the camera's trajectory from the bag's /tf and /tf_static as a TUM file");
  gt->add_option("file", args->bag, "ROS 1 bag")->required();
  gt->add_option("--out", args->out, "TUM trajectory file to write (e.g. groundtruth.txt)")->required();
  gt->add_option("--parent", args->options.parent, "Fixed frame (TUM bags: world, the motion-capture frame)")
      ->capture_default_str();
  gt->add_option("--child", args->options.child,
                 "Camera frame (default: the frame_id of the colour images)");
  gt->add_option("--rgb-topic", args->options.rgb_topic, "Colour topic, for the default camera frame")
      ->capture_default_str();
  gt->add_option("--max-gap", args->options.max_gap_s,
                 "Longest gap in seconds between two samples of a moving transform to interpolate over")
      ->capture_default_str();
  gt->callback([args] { WriteGroundTruth(*args); });
}

}  // namespace detslam::app
