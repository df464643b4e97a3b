// The viewer's answers as bytes: JSON for the page (counters, a frame's state and keypoints, the
// map's keyframes and trajectories), the map points as little-endian float32 triples, and a
// frame's image as JPEG with the dynamic masks and boxes drawn over it.
#pragma once

#include <string>

#include "detslam/viewer/viewer_content.h"

namespace detslam {

std::string CountersJson(const ViewerCounters& counters);
// {"seq", "index", "stamp", "state", ..., "pose": [12 numbers] or null,
//  "keypoints": {"matched": [x, y, ...], ...} or null}
std::string FrameJson(const ViewerFrame& frame);
// {"seq", "map_id", "points", "keyframes": [[12 numbers], ...], "trajectory": [x, y, z, ...],
//  "ground_truth": [...]} (the points themselves: MapPointsBinary)
std::string MapJson(const ViewerMap& map);
std::string MapPointsBinary(const ViewerMap& map);
// JPEG (quality 80) of the frame's image with its masks tinted cyan and its boxes drawn; empty
// when the frame has no image.
std::string FrameJpeg(const ViewerFrame& frame);

}  // namespace detslam
