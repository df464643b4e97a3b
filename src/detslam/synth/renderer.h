// Ray caster of the synthetic world: for every pixel the nearest hit among the scene's boxes and
// the people's billboards gives colour (texture x Lambert + ambient shading), depth along the
// optical axis and the instance id. Rows are rendered in parallel; each pixel depends only on the
// inputs, so the result does not depend on the thread split.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "detslam/core/camera.h"
#include "detslam/core/rigid3d.h"
#include "detslam/synth/people.h"
#include "detslam/synth/scene.h"

namespace detslam::synth {

// A noise-free rendering.
struct IdealFrame {
  cv::Mat bgr;    // CV_8UC3 colour
  cv::Mat depth;  // CV_32F depth along the optical axis (metres), 0 where nothing was hit
  cv::Mat ids;    // CV_16U instance id: 0 static scene, k for person k (or a box's instance)
  // CV_8U infrared return: the unshaded texel's grey level x the surface's InfraredGain (the
  // projector lights every surface alike; what comes back depends on the material), 0 where
  // nothing was hit. Only RenderIdealRows fills it when it is allocated.
  cv::Mat ir;
};

IdealFrame RenderIdeal(const Scene& scene, const std::vector<PersonLook>& looks,
                       const std::vector<PersonState>& people, const PinholeCamera& camera,
                       const Rigid3d& world_from_cam);

// Renders only image rows [v_begin, v_end) into `out`, whose images must already have the
// camera's size and types (a rolling shutter renders bands of rows from different poses and
// people states into one frame).
void RenderIdealRows(const Scene& scene, const std::vector<PersonLook>& looks,
                     const std::vector<PersonState>& people, const PinholeCamera& camera,
                     const Rigid3d& world_from_cam, int v_begin, int v_end, IdealFrame* out);

}  // namespace detslam::synth
