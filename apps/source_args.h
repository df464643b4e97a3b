// Where `detslam run` and `detslam densify` read their frames from: a TUM-layout folder
// (--dataset) or a ROS 1 bag (--rosbag), with the settings that go with it (--config, else the
// preset named by the folder or bag, else for a bag its camera info).
#pragma once

#include <CLI/CLI.hpp>
#include <memory>
#include <string>

#include "detslam/io/rgbd_source.h"
#include "detslam/io/rosbag_source.h"
#include "detslam/io/settings.h"

namespace detslam::app {

struct SourceArgs {
  std::string dataset;
  std::string rosbag;
  RosbagOptions bag;  // topics
  std::string config;
  std::string association;
  double max_dt = 0.02;
};

// Adds --dataset, --rosbag, the topic options, --config, --association and --max-dt (that one of
// --dataset and --rosbag is given is checked by OpenSource).
void AddSourceOptions(CLI::App* cmd, SourceArgs* args);

struct OpenedSource {
  std::unique_ptr<RgbdSource> source;
  Settings settings;
  bool bag_has_tf = false;  // a bag with /tf or /tf_static (ground truth may be in it)
};

// Opens what `args` names. Throws InputError when neither or both of --dataset and --rosbag are
// given, or when the source or the settings cannot be read.
OpenedSource OpenSource(const SourceArgs& args);

}  // namespace detslam::app
