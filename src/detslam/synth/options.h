// Options of the synthetic dynamic RGB-D sequence generator (`detslam synth`).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace detslam {

// How close to a real Kinect the rendered sensor is.
//   kEasy: the first generator: depth at the colour image's pose with i.i.d. axial noise, 3-5 %
//     missing, sharp colour (motion blur only with --blur).
//   kRealistic: a Kinect-v1-like depth camera (1/8-pixel disparity steps, correlated noise, a fixed
//     disparity distortion, projector shadow bands, mixed pixels at edges, no return from dark and
//     grazing surfaces, registration borders) rendered at the depth image's own time, and a colour
//     camera with a rolling shutter, motion blur of camera and people, lens softness,
//     signal-dependent noise and a drifting auto-exposure (synth/realistic_sensor.h); people
//     that swing their legs, turn with their walking direction, come within 0.7 m of the camera
//     and cross in front of each other (synth/people.h), and in sitting_static a laptop on the
//     desk that a sitting person pushes aside and back (class "laptop" in the masks).
enum class SynthRealism { kEasy, kRealistic };

// The realistic mode's effects that --realism-off can switch off, in a fixed order:
//   timing        depth rendered at the colour image's time instead of its own stamp
//   shutter       global shutter instead of the rolling one
//   blur          no motion blur
//   colour        no lens softness, colour noise or exposure drift
//   quantisation  continuous disparity instead of 1/8-pixel steps
//   noise         no random disparity noise
//   distortion    no fixed disparity distortion
//   dropouts      every pixel with a surface in range has depth (no borders, shadows, edges,
//                 grazing, dark or glass dropouts, holes)
//   rooms         the easy mode's busy walls and no windows
//   people        the easy mode's people: rigid sprites always facing the camera, on the easy
//                 mode's paths (no swinging legs, no turning, no close pass or crossing, no
//                 laptop moved in sitting_static)
const std::vector<std::string>& SynthRealismEffects();
// Parses a comma-separated --realism-off list into options->realism_off; throws InputError
// naming an unknown effect.
void ParseSynthRealismOff(const std::string& text, struct SynthOptions* options);

// "easy" / "realistic".
const char* SynthRealismName(SynthRealism realism);
// Parses a --realism value; throws InputError naming the valid values otherwise.
SynthRealism ParseSynthRealism(const std::string& text);

struct SynthOptions {
  std::string preset = "walking_xyz";  // camera/people script, one of SynthPresetNames()
  uint64_t seed = 1;                   // seeds textures, people and sensor noise
  // Seeds the scene's textures instead of `seed` when non-zero: two sequences with the same scene
  // seed and different seeds are two camera paths (and people, noise) through the same room.
  uint64_t scene_seed = 0;
  uint64_t SceneSeed() const { return scene_seed != 0 ? scene_seed : seed; }
  int frames = -1;                     // number of frames; <= 0: the preset's default length
  std::string people_dir;              // folder with person_*.png RGBA cut-outs; empty: procedural
  bool people = true;                  // false: the static twin (same camera path, no people)
  bool motion_blur = false;            // blur colour images along the camera's image motion
  bool sensor_noise = true;            // false: ideal depth and colour (tests of the geometry)
  // The sensor model (with sensor_noise). `detslam synth` defaults to kRealistic; the struct's
  // default stays kEasy, the fast first generator the unit and integration tests were built on.
  SynthRealism realism = SynthRealism::kEasy;
  // Effects of the realistic mode switched off, to measure what each costs (`--realism-off`):
  // names from SynthRealismEffects().
  std::vector<std::string> realism_off;
  bool RealismOff(const std::string& effect) const;
  // Frames come from the realistic sensor model (realism realistic with sensor noise on).
  bool RealisticSensor() const { return realism == SynthRealism::kRealistic && sensor_noise; }
  double depth_scale_bias = 0.0;       // F: written depth x (1 + F sin^2(pi k / (N - 1))); 0 = off
  int cut_begin = 0;                   // frames cut_begin..cut_end-1 are not written (`--cut A:B`)
  int cut_end = 0;                     // cut_end <= cut_begin (default 0, 0): no cut
  // `--cover START:SECONDS`: a covered lens from START for SECONDS (black colour, no depth; the
  // camera keeps moving and the frames are written). 0 seconds: no cover.
  double cover_start_s = 0.0;
  double cover_seconds = 0.0;

  // True if frames [cut_begin, cut_end) are to be dropped from the written sequence.
  bool HasCut() const { return cut_end > cut_begin; }
  bool HasCover() const { return cover_seconds > 0; }
  // True if frame k (30 Hz) lies under the cover: START <= k / 30 < START + SECONDS.
  bool Covered(int k) const;

  // True if the options are valid; otherwise fills `error` (may be null) with the reasons, each
  // naming its command-line option.
  bool Check(std::string* error) const;
};

// Largest |depth_scale_bias| accepted (a sensor whose depth is off by more is not plausible).
constexpr double kMaxDepthScaleBias = 0.5;

// Parses the `--cut A:B` value (two non-negative integers, A < B) into options->cut_begin and
// options->cut_end; throws InputError naming --cut otherwise. Whether the cut lies inside the
// sequence is checked by SynthOptions::Check (it needs the frame count).
void ParseSynthCut(const std::string& text, SynthOptions* options);
// Parses `--cover START:SECONDS` (two non-negative numbers, SECONDS > 0) into options->cover_*;
// throws InputError naming --cover otherwise. Check tests that it lies inside the sequence.
void ParseSynthCover(const std::string& text, SynthOptions* options);

// Scale of the written depth at frame k of a sequence of `frames` frames with bias F: it rises
// from 1 at the first frame to 1 + F at the middle and falls back to 1 at the last (sin^2 ramp).
double SynthDepthScale(double bias, int k, int frames);

// The valid preset names, in a fixed order.
const std::vector<std::string>& SynthPresetNames();

// True if `name` is a preset.
bool IsSynthPreset(const std::string& name);

// Default number of frames of a preset (30 Hz). The preset must exist.
int SynthPresetDefaultFrames(const std::string& preset);

// The number of frames the options ask for (their `frames` or the preset's default).
int SynthFrameCount(const SynthOptions& options);

// Throws InputError if the preset is unknown (the message lists the valid ones).
void RequireSynthPreset(const std::string& preset);

}  // namespace detslam
