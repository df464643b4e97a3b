// Procedural surface textures for the synthetic office: multi-scale random rectangles, blobs,
// text-like marks and material patterns, seeded per surface and never periodic, so that a FAST
// detector finds corners at several scales wherever the camera looks.
#pragma once

#include <opencv2/core.hpp>

#include "detslam/core/rng.h"

namespace detslam::synth {

enum class SurfaceKind {
  kWall,       // painted wall with notes, papers, switches, scuffs
  kFloor,      // carpet tiles with per-tile shade, speckles and litter
  kCeiling,    // ceiling tiles, light panels, sprinklers
  kWood,       // desk tops and shelves: grain, papers, keyboards, mugs
  kCardboard,  // boxes: tape, labels, printed marks
  kPoster,     // posters and whiteboards: colour blocks, figures, text
  kBooks,      // shelf fronts: book spines of random widths and colours
  kMetal,      // cabinets, legs, monitor backs: brushed grey with labels and screws
  kScreen,     // monitor fronts: windows and text on a dark background
  kPlainWall,  // freshly painted wall: uneven shading and a few small marks only
  kWindow,     // glazing: bright, soft view outside, window frames; no infrared return
};

// Share of the infrared projector's light a surface of that kind returns, relative to what its
// visible brightness suggests: 0 for glass (the pattern passes through to the far outside),
// lower for glossy screens; 1 for matte surfaces.
float InfraredGain(SurfaceKind kind);

// Texels per metre of the precomputed textures.
constexpr double kTexelsPerMetre = 256.0;

// How busy the room's own surfaces are. `room_clutter` scales the number of marks on walls,
// floor and ceiling (1: the easy generator's walls covered in notes; the realistic one uses
// fewer, so that corners gather on furniture, posters and objects as in real offices).
struct TextureStyle {
  double room_clutter = 1.0;
  bool windows = false;  // rooms get windows (the realistic mode)
};

// Makes a BGR (CV_8UC3) texture of `width_px` x `height_px` texels for a surface of that kind.
// Deterministic in the state of `rng`.
cv::Mat MakeSurfaceTexture(SurfaceKind kind, int width_px, int height_px, Rng& rng,
                           const TextureStyle& style = {});

}  // namespace detslam::synth
