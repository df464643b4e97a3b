// Moving people of the synthetic sequences: each is a vertical billboard that turns to face the
// camera, textured with a sprite (an RGBA photo cut-out or a procedural figure; alpha is the
// silhouette) and given a body-shaped depth bulge, walking along a smooth scripted path.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace detslam::synth {

// One appearance of a person: colour, silhouette and per-row horizontal extent of the silhouette.
struct Sprite {
  cv::Mat bgr;                  // CV_8UC3
  cv::Mat alpha;                // CV_8U, > 127 inside the person
  std::vector<float> row_mid;   // per row: centre column of the silhouette (or -1: empty row)
  std::vector<float> row_half;  // per row: half width of the silhouette in columns
};

// A person's look: one sprite (a photo) or a gait cycle of sprites (procedural walker).
struct PersonLook {
  std::vector<Sprite> gait;  // indexed by gait phase; size 1 for photos
};

// Loads every *.png in `dir` (sorted by name) as an RGBA photo cut-out cropped to its silhouette.
// With `gait_phases` > 1 each photo gets that many gait sprites (SwingLegs). Throws InputError
// naming the folder if it is missing or has no PNG, or naming the file if a PNG cannot be read or
// has no alpha channel.
std::vector<PersonLook> LoadPhotoPeople(const std::string& dir, int gait_phases = 1);

// A gait sprite from a photo cut-out: the part below the hips (the lowest 40 % of the silhouette)
// is split at its middle column into two legs that swing about their hip joints by +-`angle`
// radians (positive: the left leg forward), the body above stays.
Sprite SwingLegs(const Sprite& photo, double angle);

// A procedural walker (head, hair, torso with clothing texture, swinging arms and legs) with
// `phases` gait sprites; colours and clothing are drawn from `seed`.
PersonLook MakeProceduralPerson(uint64_t seed, int phases = 8);

// Fills row_mid/row_half from the alpha channel.
void ComputeSilhouetteRows(Sprite* sprite);

// Where a person is at one instant.
struct PersonState {
  int id = 0;                 // instance id (1..N) used in the masks
  Eigen::Vector3d foot;       // billboard base centre on the floor (world, metres)
  double height = 1.7;        // billboard height (metres)
  double depth_bulge = 0.14;  // how far the body centre stands out of the billboard (metres)
  int look = 0;               // index into the looks
  int gait_phase = 0;         // index into PersonLook::gait (modulo its size)
  // Realistic people turn with their walking direction: the body's facing (world yaw, radians)
  // narrows the sprite seen from the side and mirrors it seen from behind (renderer). Without a
  // facing the sprite faces the camera at full width.
  bool has_facing = false;
  double facing_yaw = 0.0;
};

// The scripted people of a preset: positions at time t (seconds). Empty for "static".
class PeopleScript {
 public:
  // `realistic`: people turn with their walking direction, and in the walking presets one of them
  // walks up to 0.7 m from the camera and the two cross in front of each other.
  PeopleScript(const std::string& preset, uint64_t seed, bool realistic = false);
  std::vector<PersonState> At(double t) const;
  int count() const { return static_cast<int>(walkers_.size()); }

 private:
  struct Walker {
    Eigen::Vector2d centre;  // middle of the walk (world x, y)
    Eigen::Vector2d axis;    // unit direction of the walk
    double amplitude;        // half length of the walk (metres)
    double period;           // seconds for one back-and-forth
    double phase;            // radians
    double sway;             // sideways sway amplitude (metres)
    double height;           // metres
    bool sitting;            // small motions only, no gait
  };
  std::vector<Walker> walkers_;
  bool realistic_ = false;
};

}  // namespace detslam::synth
