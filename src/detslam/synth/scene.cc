#include "detslam/synth/scene.h"

#include "detslam/synth/options.h"
#include "detslam/synth/scene_builder.h"

namespace detslam::synth {

Scene BuildOfficeScene(uint64_t seed, const TextureStyle& style) {
  SceneBuilder b(seed ^ 0x5CE4EULL, style);
  using V = Eigen::Vector3f;
  const SurfaceKind W = SurfaceKind::kWall, F = SurfaceKind::kFloor, C = SurfaceKind::kCeiling;
  // Room shell (6.0 x 5.4 x 2.8 m). Floor is the z-lo face, ceiling the z-hi face.
  {
    // Interior box: walls use kWall; the z faces are set by `special` tricks below.
    b.Box(V(-3.0f, -2.8f, 0.0f), V(3.0f, 2.6f, 2.8f), W, C, FaceIndex(2, false), F, true);
  }
  // Central table where two people can sit on the far side, with a front panel and monitors.
  b.Desk(-1.3f, 1.3f, 0.6f, 1.9f, true);
  b.Monitor(-1.0f, 1.2f, 0.755f, true);
  b.Monitor(1.0f, 1.2f, 0.755f, true);
  b.Box(V(-0.35f, 0.75f, 0.755f), V(0.15f, 0.92f, 0.78f), SurfaceKind::kMetal,
        SurfaceKind::kScreen);
  b.Box(V(0.3f, 0.7f, 0.755f), V(0.62f, 1.0f, 0.765f), SurfaceKind::kPoster, SurfaceKind::kPoster);
  b.Box(V(-0.7f, 0.8f, 0.755f), V(-0.6f, 0.9f, 0.87f), SurfaceKind::kCardboard,
        SurfaceKind::kMetal);
  // Side desk along the left wall with a monitor and boxes below.
  b.Desk(-3.0f, -2.25f, -1.6f, 0.9f, false);
  b.Monitor(-2.85f, -0.4f, 0.755f, false);
  b.Box(V(-2.9f, 0.1f, 0.0f), V(-2.4f, 0.6f, 0.42f), SurfaceKind::kCardboard,
        SurfaceKind::kCardboard);
  b.Box(V(-2.9f, -1.4f, 0.755f), V(-2.55f, -1.0f, 0.95f), SurfaceKind::kCardboard,
        SurfaceKind::kCardboard);
  // Far wall: two shelves full of books and posters between them.
  b.Box(V(-2.8f, 2.2f, 0.0f), V(-1.45f, 2.6f, 2.0f), SurfaceKind::kWood, SurfaceKind::kWood,
        FaceIndex(1, false), SurfaceKind::kBooks);
  b.Box(V(1.45f, 2.25f, 0.0f), V(2.8f, 2.6f, 1.75f), SurfaceKind::kWood, SurfaceKind::kCardboard,
        FaceIndex(1, false), SurfaceKind::kBooks);
  b.Box(V(-1.0f, 2.57f, 1.3f), V(0.15f, 2.6f, 2.15f), W, W, FaceIndex(1, false),
        SurfaceKind::kPoster);
  b.Box(V(0.35f, 2.57f, 1.05f), V(1.15f, 2.6f, 1.95f), W, W, FaceIndex(1, false),
        SurfaceKind::kPoster);
  // Right wall: cabinet, whiteboard, stacked boxes, a door.
  b.Box(V(2.5f, -1.0f, 0.0f), V(3.0f, 0.2f, 1.1f), SurfaceKind::kMetal, SurfaceKind::kWood);
  b.Box(V(2.97f, 0.4f, 0.9f), V(3.0f, 2.0f, 2.0f), W, W, FaceIndex(0, false), SurfaceKind::kPoster);
  b.Box(V(2.2f, 1.0f, 0.0f), V(2.8f, 1.6f, 0.5f), SurfaceKind::kCardboard, SurfaceKind::kCardboard);
  b.Box(V(2.3f, 1.1f, 0.5f), V(2.7f, 1.5f, 0.82f), SurfaceKind::kCardboard,
        SurfaceKind::kCardboard);
  b.Box(V(2.96f, -2.3f, 0.0f), V(3.0f, -1.4f, 2.1f), SurfaceKind::kWood, SurfaceKind::kWood,
        FaceIndex(0, false), SurfaceKind::kWood);
  // Back wall (behind the default camera): shelf, posters, boxes.
  b.Box(V(-1.1f, -2.8f, 0.0f), V(0.9f, -2.42f, 1.9f), SurfaceKind::kWood, SurfaceKind::kWood,
        FaceIndex(1, true), SurfaceKind::kBooks);
  b.Box(V(1.3f, -2.8f, 1.0f), V(2.3f, -2.77f, 1.9f), W, W, FaceIndex(1, true),
        SurfaceKind::kPoster);
  b.Box(V(-2.6f, -2.8f, 0.0f), V(-1.9f, -2.2f, 0.6f), SurfaceKind::kCardboard,
        SurfaceKind::kCardboard);
  b.Box(V(1.6f, -2.6f, 0.0f), V(2.2f, -2.1f, 0.75f), SurfaceKind::kMetal, SurfaceKind::kWood);
  // Left wall posters.
  b.Box(V(-3.0f, 1.2f, 1.2f), V(-2.97f, 2.1f, 2.05f), W, W, FaceIndex(0, true),
        SurfaceKind::kPoster);
  b.Box(V(-3.0f, -2.5f, 1.3f), V(-2.97f, -1.8f, 2.0f), W, W, FaceIndex(0, true),
        SurfaceKind::kPoster);
  if (style.windows) {
    // Windows (added last, so the other surfaces keep their textures): a band of high windows
    // along the far wall, one above the left desk, one above the right cabinet, one in the back.
    const SurfaceKind G = SurfaceKind::kWindow;
    b.Box(V(-2.8f, 2.59f, 1.6f), V(2.8f, 2.6f, 2.7f), W, W, FaceIndex(1, false), G);
    b.Box(V(-3.0f, -1.5f, 1.8f), V(-2.99f, 0.9f, 2.5f), W, W, FaceIndex(0, true), G);
    b.Box(V(2.99f, -0.9f, 1.8f), V(3.0f, 0.3f, 2.5f), W, W, FaceIndex(0, false), G);
    b.Box(V(-2.7f, -2.8f, 1.0f), V(-1.3f, -2.79f, 2.5f), W, W, FaceIndex(1, true), G);
  }
  return b.Take();
}

}  // namespace detslam::synth

namespace detslam::synth {

Scene BuildSceneForPreset(const std::string& preset, uint64_t seed, const TextureStyle& style) {
  RequireSynthPreset(preset);
  if (preset == "loop_long") return BuildLargeOfficeScene(seed, style);
  if (preset == "lookalike") return BuildLookalikeScene(seed, style).scene;
  return BuildOfficeScene(seed, style);
}

}  // namespace detslam::synth
