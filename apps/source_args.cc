#include "source_args.h"

#include "detslam/core/check.h"
#include "detslam/io/dataset.h"

namespace detslam::app {

void AddSourceOptions(CLI::App* cmd, SourceArgs* args) {
  auto* dataset = cmd->add_option("--dataset", args->dataset, "Folder with rgb.txt, depth.txt (and groundtruth.txt)");
  cmd->add_option("--rosbag", args->rosbag,
                  "ROS 1 bag (format 2.0; uncompressed, bz2 or lz4 chunks) with colour and depth sensor_msgs/Image topics, instead of --dataset")
      ->excludes(dataset);
  cmd->add_option("--rgb-topic", args->bag.rgb_topic, "With --rosbag: colour topic (rgb8, bgr8, rgba8, bgra8, mono8)")->capture_default_str();
  cmd->add_option("--depth-topic", args->bag.depth_topic, "With --rosbag: depth topic (32FC1 metres or 16UC1 millimetres)")->capture_default_str();
  cmd->add_option("--camera-info-topic", args->bag.camera_info_topic,
                  "With --rosbag: camera intrinsics, used when there is no --config and the bag's file name names no preset")
      ->capture_default_str();
  cmd->add_option("--config", args->config, "ORB-SLAM3-style settings YAML (default: preset from the folder or bag name; for a bag otherwise its camera info)");
  cmd->add_option("--association", args->association, "Explicit rgb/depth association file");
  cmd->add_option("--max-dt", args->max_dt, "rgb/depth association window in seconds")->capture_default_str();
}

OpenedSource OpenSource(const SourceArgs& a) {
  if (a.dataset.empty() == a.rosbag.empty()) {
    throw InputError("name the frames to run on: --dataset DIR (TUM layout) or --rosbag FILE");
  }
  OpenedSource out;
  if (!a.rosbag.empty()) {
    if (!a.association.empty()) throw InputError("--association is for --dataset folders only");
    RosbagOptions bopt = a.bag;
    bopt.max_difference_s = a.max_dt;
    auto bag = std::make_unique<RosbagSource>(RosbagSource::Open(a.rosbag, bopt));
    out.settings = a.config.empty() ? SettingsForBag(a.rosbag, bag->camera_info()) : ReadSettings(a.config);
    out.bag_has_tf = bag->has_tf();
    out.source = std::move(bag);
  } else {
    DatasetOptions dopt;
    dopt.max_difference_s = a.max_dt;
    dopt.association_file = a.association;
    out.source = std::make_unique<RgbdDataset>(RgbdDataset::Open(a.dataset, dopt));
    out.settings = a.config.empty() ? PresetForDataset(a.dataset) : ReadSettings(a.config);
  }
  return out;
}

}  // namespace detslam::app
