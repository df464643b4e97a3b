// `detslam map info FILE`: what a map file written by `detslam run --save-map` holds (format
// version, camera, ORB pyramid, vocabulary checksum, keyframes, map points), after checking it
// whole (checksum and structure).
#include <cinttypes>
#include <cstdio>
#include <memory>
#include <string>

#include "commands.h"
#include "detslam/map/map_file.h"

namespace detslam::app {
namespace {

void PrintMapInfo(const std::string& path) {
  const MapFileInfo info = ReadMapFileInfo(path);
  const PinholeCamera& c = info.camera;
  std::printf("%s: detslam map file, format version %u, %" PRIu64 " bytes\n", path.c_str(),
              info.version, info.bytes);
  std::printf("camera: %dx%d, fx %.3f fy %.3f cx %.3f cy %.3f, distortion %g %g %g %g %g, bf %.3f\n",
              c.width, c.height, c.fx, c.fy, c.cx, c.cy, c.k1, c.k2, c.p1, c.p2, c.k3, c.bf);
  std::printf("ORB pyramid: %d levels, scale factor %.3f\n", info.levels, info.scale_factor);
  if (info.vocabulary_checksum != 0) {
    std::printf("vocabulary checksum: %016" PRIx64 "\n", info.vocabulary_checksum);
  } else {
    std::printf("vocabulary: none (made without place recognition)\n");
  }
  std::printf("keyframes: %" PRIu64 ", map points: %" PRIu64 "\n", info.keyframes, info.landmarks);
}

}  // namespace

void AddMapCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("map", "Inspect map files written by `detslam run --save-map`");
  cmd->require_subcommand(1);
  auto* info = cmd->add_subcommand("info", "Check a map file and print what it holds");
  auto file = std::make_shared<std::string>();
  info->add_option("file", *file, "Map file")->required();
  info->callback([file] { PrintMapInfo(*file); });
}

}  // namespace detslam::app
