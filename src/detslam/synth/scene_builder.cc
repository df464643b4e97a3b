#include "detslam/synth/scene_builder.h"

#include <cmath>

namespace detslam::synth {

int SceneBuilder::Box(Eigen::Vector3f lo, Eigen::Vector3f hi, SurfaceKind sides, SurfaceKind top,
                      int special_face, SurfaceKind special, bool interior) {
  return AddBox(lo, hi, Textures(hi - lo, sides, top, special_face, special), interior);
}

std::array<int, 6> SceneBuilder::Textures(const Eigen::Vector3f& extent, SurfaceKind sides,
                                          SurfaceKind top, int special_face, SurfaceKind special) {
  std::array<int, 6> faces{};
  for (int axis = 0; axis < 3; ++axis) {
    const int ua = axis == 0 ? 1 : 0;
    const int va = axis == 2 ? 1 : 2;
    const int w = static_cast<int>(std::ceil(extent[ua] * kTexelsPerMetre)) + 2;
    const int h = static_cast<int>(std::ceil(extent[va] * kTexelsPerMetre)) + 2;
    for (int side = 0; side < 2; ++side) {
      const int face = FaceIndex(axis, side == 1);
      SurfaceKind kind = (axis == 2 && side == 1) ? top : sides;
      if (face == special_face) kind = special;
      Rng surface_rng = rng_.Fork(static_cast<uint64_t>(scene_.textures.size()) + 1);
      faces[face] = static_cast<int>(scene_.textures.size());
      scene_.textures.push_back(MakeSurfaceTexture(kind, w, h, surface_rng, style_));
      scene_.ir_gain.push_back(InfraredGain(kind));
    }
  }
  return faces;
}

int SceneBuilder::AddBox(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi,
                         const std::array<int, 6>& textures, bool interior) {
  SceneBox b;
  b.lo = lo;
  b.hi = hi;
  b.interior = interior;
  b.texture = textures;
  scene_.boxes.push_back(b);
  return static_cast<int>(scene_.boxes.size()) - 1;
}

void SceneBuilder::Desk(float x0, float x1, float y0, float y1, bool panel) {
  const float top = 0.72f, th = 0.035f, leg = 0.05f;
  Box({x0, y0, top}, {x1, y1, top + th}, SurfaceKind::kWood, SurfaceKind::kWood);
  for (float x : {x0 + 0.03f, x1 - 0.03f - leg}) {
    for (float y : {y0 + 0.03f, y1 - 0.03f - leg}) {
      Box({x, y, 0.f}, {x + leg, y + leg, top}, SurfaceKind::kMetal, SurfaceKind::kMetal);
    }
  }
  if (panel) {
    Box({x0 + 0.08f, y0 + 0.04f, 0.28f}, {x1 - 0.08f, y0 + 0.07f, top}, SurfaceKind::kMetal,
        SurfaceKind::kMetal);
  }
}

void SceneBuilder::Monitor(float cx, float cy, float z, bool faces_minus_y) {
  const float w = 0.27f, d = 0.025f;
  if (faces_minus_y) {
    Box({cx - w, cy, z + 0.1f}, {cx + w, cy + d, z + 0.45f}, SurfaceKind::kMetal,
        SurfaceKind::kMetal, FaceIndex(1, false), SurfaceKind::kScreen);
    Box({cx - 0.03f, cy + d, z}, {cx + 0.03f, cy + d + 0.04f, z + 0.12f}, SurfaceKind::kMetal,
        SurfaceKind::kMetal);
  } else {
    Box({cx, cy - w, z + 0.1f}, {cx + d, cy + w, z + 0.45f}, SurfaceKind::kMetal,
        SurfaceKind::kMetal, FaceIndex(0, true), SurfaceKind::kScreen);
  }
}

}  // namespace detslam::synth
