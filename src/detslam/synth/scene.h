// The static synthetic world: an office-like room (walls, floor, ceiling) furnished with
// axis-aligned boxes (desks, monitors, shelves, cabinets, cardboard boxes, posters), each face with
// its own precomputed procedural texture, plus one point light for Lambert + ambient shading.
// World frame: x right, y forward (away from the default camera), z up; metres.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

#include "detslam/synth/texture.h"

namespace detslam::synth {

// Face index of an axis-aligned box: 2 * axis + (0 for the face at lo[axis], 1 at hi[axis]).
inline int FaceIndex(int axis, bool hi_side) { return 2 * axis + (hi_side ? 1 : 0); }

struct SceneBox {
  Eigen::Vector3f lo;            // minimum corner (metres, world)
  Eigen::Vector3f hi;            // maximum corner (metres, world)
  bool interior = false;         // true for the room shell, which is seen from inside
  std::array<int, 6> texture{};  // index into Scene::textures for each face (FaceIndex)
  uint16_t instance = 0;         // id of its pixels in the instance mask (0: the static scene)
};

struct Scene {
  std::vector<SceneBox> boxes;            // boxes[0] is the room shell
  std::vector<cv::Mat> textures;          // CV_8UC3, kTexelsPerMetre texels per metre
  std::vector<float> ir_gain;             // per texture: InfraredGain of its kind (missing = 1)
  Eigen::Vector3f light{0.f, 0.f, 2.6f};  // point light position (world)
  float ambient = 0.45f;                  // ambient share of the shading
};

// Texture coordinates (texels) of world point `p` on face (axis, hi_side) of `box`: column from
// the face's first in-plane axis, row from the second (rows grow downwards on vertical faces).
inline void FaceTexel(const SceneBox& box, int axis, const Eigen::Vector3f& p, float* col,
                      float* row) {
  const int ua = axis == 0 ? 1 : 0;
  const int va = axis == 2 ? 1 : 2;
  const float s = static_cast<float>(kTexelsPerMetre);
  *col = (p[ua] - box.lo[ua]) * s;
  *row = axis == 2 ? (p[va] - box.lo[va]) * s : (box.hi[va] - p[va]) * s;
}

// Builds the office room; textures are seeded from `seed` (one forked generator per surface).
Scene BuildOfficeScene(uint64_t seed, const TextureStyle& style = {});

// A large office (12.6 x 8.4 x 2.8 m) for the loop_long preset: the walls lined with shelves,
// cabinets, cardboard boxes and posters (a seeded layout), the middle free for the camera.
Scene BuildLargeOfficeScene(uint64_t seed, const TextureStyle& style = {});

// The lookalike preset's room (12.8 x 5.0 x 2.8 m): two parts along the far wall (y = 2.6) with
// the same furnishings' textures in different layouts, and a neutral stretch between them.
struct LookalikeScene {
  Scene scene;
  // Pairs (box in the first part, box in the second part) that share all face textures; their
  // positions and sizes differ, and no two pairs keep their relative placement.
  std::vector<std::pair<int, int>> twins;
  static constexpr float kFirstPartMaxX = -0.9f;  // the first part lies at x < this (world)
  static constexpr float kSecondPartMinX = 0.9f;  // the second part lies at x > this (world)
};
LookalikeScene BuildLookalikeScene(uint64_t seed, const TextureStyle& style = {});

// The room of a preset (the office for the TUM-like presets and `loop`).
Scene BuildSceneForPreset(const std::string& preset, uint64_t seed,
                          const TextureStyle& style = {});

}  // namespace detslam::synth
