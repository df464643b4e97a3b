// The rooms of the place-recognition presets: a large office for `loop_long` (see scene.h).
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "detslam/core/rng.h"
#include "detslam/synth/scene.h"
#include "detslam/synth/scene_builder.h"

namespace detslam::synth {
namespace {

using V = Eigen::Vector3f;

// A wall of a room seen from inside: the plane `axis` = `at` (axis 0 or 1), the room on the side
// `inward` (+1: larger coordinates).
struct Wall {
  int axis = 0;
  float at = 0.f;
  float inward = 1.f;
};

// A box standing against `wall`: [s0, s1] along the wall, `depth` into the room, z in [z0, z1];
// its face towards the room uses `front`.
void WallBox(SceneBuilder& b, const Wall& wall, float s0, float s1, float depth, float z0, float z1,
             SurfaceKind sides, SurfaceKind top, SurfaceKind front) {
  const int along = 1 - wall.axis;
  V lo, hi;
  lo[along] = s0;
  hi[along] = s1;
  lo[2] = z0;
  hi[2] = z1;
  lo[wall.axis] = wall.inward > 0 ? wall.at : wall.at - depth;
  hi[wall.axis] = wall.inward > 0 ? wall.at + depth : wall.at;
  b.Box(lo, hi, sides, top, FaceIndex(wall.axis, wall.inward > 0), front);
}

// Lines `wall` between s0 and s1 with a seeded mix of bookshelves, cabinets and cardboard boxes
// (often with a poster above), doors and posters, with gaps of bare wall between them.
void FurnishWall(SceneBuilder& b, Rng& rng, const Wall& wall, float s0, float s1) {
  const auto u = [&](double lo, double hi) { return static_cast<float>(rng.Uniform(lo, hi)); };
  float s = s0 + u(0.05, 0.4);
  while (s < s1 - 0.4f) {
    const float width = std::min(u(0.5, 1.4), s1 - s);
    const double kind = rng.Uniform();
    if (kind < 0.22) {
      WallBox(b, wall, s, s + width, 0.38f, 0.f, u(1.5, 2.0), SurfaceKind::kWood,
              SurfaceKind::kWood, SurfaceKind::kBooks);
    } else if (kind < 0.62) {
      const bool cabinet = rng.Uniform() < 0.5;
      const float top = u(0.45, 1.1);
      const SurfaceKind material = cabinet ? SurfaceKind::kMetal : SurfaceKind::kCardboard;
      WallBox(b, wall, s, s + width, cabinet ? 0.5f : u(0.35, 0.6), 0.f, top, material,
              cabinet ? SurfaceKind::kWood : SurfaceKind::kCardboard, material);
      if (rng.Uniform() < 0.7) {
        const float z0 = top + u(0.15, 0.35);
        WallBox(b, wall, s + u(0.0, 0.15), s + width - u(0.0, 0.15), 0.03f, z0,
                std::min(2.4f, z0 + u(0.5, 0.9)), SurfaceKind::kWall, SurfaceKind::kWall,
                SurfaceKind::kPoster);
      }
    } else if (kind < 0.75) {
      WallBox(b, wall, s, s + std::min(width, 0.95f), 0.05f, 0.f, 2.1f, SurfaceKind::kWood,
              SurfaceKind::kWood, SurfaceKind::kWood);
    } else {
      const float z0 = u(0.9, 1.3);
      WallBox(b, wall, s, s + width, 0.03f, z0, z0 + u(0.5, 1.0), SurfaceKind::kWall,
              SurfaceKind::kWall, SurfaceKind::kPoster);
    }
    s += width + u(0.1, 0.6);
  }
}

}  // namespace

Scene BuildLargeOfficeScene(uint64_t seed) {
  SceneBuilder b(seed ^ 0x1A26EULL);
  Rng layout(seed ^ 0x1A40FULL);
  const float hx = 6.3f, hy = 4.2f;
  b.Box(V(-hx, -hy, 0.f), V(hx, hy, 2.8f), SurfaceKind::kWall, SurfaceKind::kCeiling,
        FaceIndex(2, false), SurfaceKind::kFloor, true);
  // The walls in the order the loop passes them; corners (0.75 m) stay free.
  const Wall walls[4] = {{1, -hy, 1.f}, {0, hx, -1.f}, {1, hy, -1.f}, {0, -hx, 1.f}};
  for (const Wall& wall : walls) {
    const float half = wall.axis == 1 ? hx : hy;
    FurnishWall(b, layout, wall, -half + 0.75f, half - 0.75f);
  }
  return b.Take();
}

}  // namespace detslam::synth
