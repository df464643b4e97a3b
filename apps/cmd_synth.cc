// detslam synth: writes a synthetic dynamic RGB-D sequence (TUM layout, ground-truth poses and
// per-frame masks of the moving people); see src/detslam/synth/writer.h for the files.
#include <nlohmann/json.hpp>

#include "commands.h"
#include "detslam/core/atomic_file.h"
#include "detslam/core/check.h"
#include "detslam/synth/options.h"
#include "detslam/synth/writer.h"

namespace detslam::app {

void AddSynthCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("synth", "Write a synthetic dynamic RGB-D sequence (TUM layout)");
  auto opts = std::make_shared<SynthOptions>();
  auto out_dir = std::make_shared<std::string>();
  auto stats_json = std::make_shared<std::string>();
  auto no_people = std::make_shared<bool>(false);
  auto cut = std::make_shared<std::string>();
  auto cover = std::make_shared<std::string>();
  auto realism = std::make_shared<std::string>("realistic");
  auto realism_off = std::make_shared<std::string>();
  std::string presets;
  for (const auto& p : SynthPresetNames()) presets += (presets.empty() ? "" : ", ") + p;
  cmd->add_option("--preset", opts->preset, "Camera/people script: " + presets)
      ->capture_default_str();
  cmd->add_option("--seed", opts->seed, "Seed of textures, people and sensor noise")
      ->capture_default_str();
  cmd->add_option("--scene-seed", opts->scene_seed,
                  "Seed of the scene's textures (default: --seed); the same scene seed with another "
                  "--seed gives another camera path through the same room");
  cmd->add_option("--frames", opts->frames, "Number of frames (default: the preset's length)");
  cmd->add_option("--people", opts->people_dir,
                  "Folder of RGBA person cut-outs (*.png, alpha = silhouette) to texture people");
  cmd->add_flag("--no-people", *no_people, "Static twin: same camera path, no moving people");
  cmd->add_flag("--blur", opts->motion_blur,
                "Motion blur from the camera velocity (easy mode; the realistic sensor always "
                "blurs by camera and people motion)");
  cmd->add_option("--realism", *realism,
                  "Sensor model: 'easy' (i.i.d. axial depth noise, 3-5 % missing depth, sharp "
                  "colour) or 'realistic' (Kinect-v1-like depth at its own timestamp: 1/8 px "
                  "disparity steps, correlated noise, distortion, projector shadows, mixed edge "
                  "pixels, no return from dark or grazing surfaces, registration borders; rolling "
                  "shutter, motion blur, lens softness, photon noise, exposure drift; people "
                  "who swing their legs, turn, come close and cross; a laptop moved in "
                  "sitting_static)")
      ->capture_default_str();
  std::string effects;
  for (const auto& e : SynthRealismEffects()) effects += (effects.empty() ? "" : ", ") + e;
  cmd->add_option("--realism-off", *realism_off,
                  "Comma-separated effects of the realistic mode to switch off, to measure what "
                  "each costs: " + effects);
  cmd->add_option("--depth-scale-bias", opts->depth_scale_bias,
                  "Depth miscalibration F: written depth x 1 + F sin^2(pi k / (frames - 1)) (rises "
                  "to 1 + F mid-sequence, back to 1 at the end; ground truth stays true); 0 = off")
      ->capture_default_str();
  cmd->add_option("--cut", *cut,
                  "A:B drops frames A..B-1 from the written sequence (the camera keeps moving: "
                  "frame A-1 is followed by frame B, a kidnapped camera)");
  cmd->add_option("--cover", *cover,
                  "START:SECONDS covers the lens from START for SECONDS: black colour images and "
                  "no depth while the camera keeps moving (e.g. 8:2 on the roam preset hides its "
                  "turn towards the unseen back of the room)");
  cmd->add_option("--out", *out_dir, "Output folder")->required();
  cmd->add_option("--stats-json", *stats_json,
                  "Write timing and content statistics (fps, FAST corners, coverage) as JSON");
  cmd->callback([opts, out_dir, stats_json, no_people, cut, cover, realism, realism_off] {
    opts->people = !*no_people;
    opts->realism = ParseSynthRealism(*realism);
    if (!realism_off->empty()) ParseSynthRealismOff(*realism_off, opts.get());
    if (!cut->empty()) ParseSynthCut(*cut, opts.get());
    if (!cover->empty()) ParseSynthCover(*cover, opts.get());
    RequireSynthPreset(opts->preset);
    std::string error;
    if (!opts->Check(&error)) throw InputError("detslam synth: " + error);
    const SynthStats s = WriteSequence(*opts, *out_dir);
    if (!stats_json->empty()) {
      const nlohmann::json cut_frames =
          opts->HasCut() ? nlohmann::json::array({opts->cut_begin, opts->cut_end})
                         : nlohmann::json();
      nlohmann::json j = {{"preset", opts->preset},
                          {"seed", opts->seed},
                          {"scene_seed", opts->SceneSeed()},
                          {"people", opts->people},
                          {"people_dir", opts->people_dir},
                          {"motion_blur", opts->motion_blur},
                          {"realism", SynthRealismName(opts->realism)},
                          {"realism_off", opts->realism_off},
                          {"depth_scale_bias", opts->depth_scale_bias},
                          {"cut", cut_frames},
                          {"cover", opts->HasCover() ? nlohmann::json::array(
                                                           {opts->cover_start_s,
                                                            opts->cover_seconds})
                                                     : nlohmann::json()},
                          {"frames", s.frames},
                          {"render_seconds", s.render_seconds},
                          {"total_seconds", s.total_seconds},
                          {"render_fps", s.render_fps},
                          {"total_fps", s.total_fps},
                          {"mean_fast20_corners", s.mean_fast_corners},
                          {"fast_sampled_frames", s.sampled_frames},
                          {"mean_missing_depth", s.mean_missing_depth},
                          {"mean_people_coverage", s.mean_coverage}};
      WriteFileAtomically(*stats_json, [&](std::ostream& os) { os << j.dump(2) << "\n"; });
    }
  });
}

}  // namespace detslam::app
