// Building blocks of the synthetic rooms (internal to synth/): boxes with one seeded procedural
// texture per face, desks and monitors. Textures are drawn in the order the boxes are added, one
// forked generator per texture, so a room is a pure function of its seed and construction order.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <utility>

#include "detslam/core/rng.h"
#include "detslam/synth/scene.h"
#include "detslam/synth/texture.h"

namespace detslam::synth {

class SceneBuilder {
 public:
  explicit SceneBuilder(uint64_t seed, const TextureStyle& style = {})
      : rng_(seed), style_(style) {}
  // Goes on building `existing` (its boxes and textures kept), with textures seeded from `seed`.
  SceneBuilder(uint64_t seed, Scene existing, const TextureStyle& style = {})
      : rng_(seed), style_(style), scene_(std::move(existing)) {}

  // Adds a box whose faces use `sides` texture, the top (+z) face `top`; `special_face` (if >= 0)
  // uses `special`. Returns the box's index.
  int Box(Eigen::Vector3f lo, Eigen::Vector3f hi, SurfaceKind sides, SurfaceKind top,
          int special_face = -1, SurfaceKind special = SurfaceKind::kPoster, bool interior = false);

  // Makes the six face textures of a box of size `extent` (metres) without adding a box (for
  // boxes that share textures: each face of a box at most `extent` large shows a crop of them).
  std::array<int, 6> Textures(const Eigen::Vector3f& extent, SurfaceKind sides, SurfaceKind top,
                              int special_face = -1, SurfaceKind special = SurfaceKind::kPoster);

  // Adds a box with the given face textures (indices into the scene's textures). Returns its index.
  int AddBox(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi,
             const std::array<int, 6>& textures, bool interior = false);

  // A desk: top slab, four legs, optional front panel.
  void Desk(float x0, float x1, float y0, float y1, bool panel);

  // A monitor standing on a desk at height z, screen facing -y (towards the default camera) if
  // `faces_minus_y`, else facing -x.
  void Monitor(float cx, float cy, float z, bool faces_minus_y);

  Scene& scene() { return scene_; }
  // The generator the textures are forked from (for further draws of the same seed).
  Rng& rng() { return rng_; }
  Scene Take() { return std::move(scene_); }

 private:
  Rng rng_;
  TextureStyle style_;
  Scene scene_;
};

}  // namespace detslam::synth
