// detslam segment: runs the OpenCV-dnn segmenter (detector + per-box person masks) over a
// TUM/Bonn-layout dataset and writes a masks folder (format: src/detslam/segmentation/mask_dir.h)
// that `detslam run --segmenter masks:DIR` reads, so a sequence is segmented once and run many
// times.
#include <chrono>
#include <cstdio>
#include <memory>

#include "commands.h"
#include "detslam/core/check.h"
#include "detslam/io/dataset.h"
#include "detslam/io/settings.h"
#include "detslam/pipeline/settings_keys.h"
#include "detslam/segmentation/dnn_segmenter.h"
#include "detslam/segmentation/mask_dir.h"

namespace detslam::app {
namespace {

struct SegmentArgs {
  std::string dataset;
  std::string config;
  std::string models;
  std::string detector;
  std::string out;
  int64_t max_frames = -1;
  bool no_person_mask = false;
  std::vector<std::string> overrides;  // --set KEY=VALUE
};

void Segment(const SegmentArgs& a) {
  const RgbdDataset dataset = RgbdDataset::Open(a.dataset, DatasetOptions());
  Settings settings = a.config.empty() ? PresetForDataset(a.dataset) : ReadSettings(a.config);
  ApplySettingOverrides(a.overrides, &settings);
  const std::string models = a.models.empty() ? DefaultModelsDir() : a.models;
  DnnSegmenterOptions options = DnnOptionsFromSettings(ResolveSettings(settings).segmenter, models);
  if (!a.detector.empty()) {
    options.detector_path = a.detector;
    options.weights_path.clear();
    options.names_path.clear();
    ResolveModelCompanions(&options);
  }
  if (a.no_person_mask) options.person_mask_model.clear();
  DnnSegmenter segmenter(options);
  const size_t n =
      a.max_frames >= 0 ? std::min<size_t>(dataset.size(), a.max_frames) : dataset.size();
  std::fprintf(stderr, "detslam segment: %zu frames from %s with %s -> %s\n", n,
               dataset.dir().c_str(), segmenter.name().c_str(), a.out.c_str());
  MaskDirWriter writer(a.out,
                       "made by detslam segment (" + segmenter.name() + ") from " + dataset.dir());
  double detect_ms = 0, mask_ms = 0;
  const auto start = std::chrono::steady_clock::now();
  for (size_t i = 0; i < n; ++i) {
    const RgbdImages images = dataset.Load(i, settings.camera);
    SegmenterInput input;
    input.index = static_cast<int64_t>(i);
    input.stamp = dataset.frame(i).rgb_stamp;
    input.bgr = images.bgr;
    input.depth_m = images.depth_m;
    const std::vector<Instance> instances = segmenter.Segment(input);
    detect_ms += segmenter.last_timings().detect_ms;
    mask_ms += segmenter.last_timings().mask_ms;
    writer.Add(input.stamp, images.bgr.size(), instances);
    if ((i + 1) % 20 == 0 || i + 1 == n) {
      const double s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::fprintf(stderr, "[segment] %zu/%zu frames, %d instances, %.1f frames/s\n", i + 1, n,
                   writer.instances(), (i + 1) / std::max(s, 1e-9));
      writer.Flush();
    }
  }
  writer.Finish();
  const double frames = std::max<double>(1, n);
  std::printf("segmented %zu frames: %d instances; mean ms per frame: detect %.1f, masks %.1f\n", n,
              writer.instances(), detect_ms / frames, mask_ms / frames);
  std::printf("masks: %s (use: detslam run --segmenter masks:%s)\n", a.out.c_str(), a.out.c_str());
}

}  // namespace

void AddSegmentCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "segment", "Segment a dataset once (detector + person masks) into a masks folder");
  auto a = std::make_shared<SegmentArgs>();
  cmd->add_option("--dataset", a->dataset, "TUM/Bonn-layout RGB-D folder")->required();
  cmd->add_option("--config", a->config,
                  "Settings YAML (camera; Segmentation.* keys); default: preset for the folder");
  cmd->add_option("--models", a->models,
                  "Models folder (default: $DETSLAM_MODELS or the build's shared/models)");
  cmd->add_option("--detector", a->detector,
                  "Detector: YOLOX .onnx or Darknet .cfg (weights and names beside it)");
  cmd->add_option("--out", a->out, "Output masks folder")->required();
  cmd->add_option("--max-frames", a->max_frames, "Segment at most this many frames");
  cmd->add_option("--set", a->overrides,
                  "Override a settings key, KEY=VALUE (repeatable), e.g. "
                  "--set Segmentation.SecondDetector=none");
  cmd->add_flag("--no-person-mask", a->no_person_mask,
                "Skip the person mask model (masks = box pixels at the dominant depth)");
  cmd->callback([a] { Segment(*a); });
}

}  // namespace detslam::app
