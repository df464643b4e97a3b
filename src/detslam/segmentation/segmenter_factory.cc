#include "detslam/segmentation/segmenter_factory.h"

#include <filesystem>

#include "detslam/core/check.h"
#include "detslam/segmentation/dnn_segmenter.h"
#include "detslam/segmentation/mask_dir.h"
#include "detslam/segmentation/mask_rcnn_segmenter.h"

namespace detslam {

SegmenterSettings ForCameraRate(SegmenterSettings settings) {
  settings.dnn.yolox_input_size = settings.camera_rate_input_size;
  return settings;
}

std::unique_ptr<Segmenter> MakeSegmenter(const std::string& spec, const std::string& dataset_dir,
                                         const SegmenterSettings& settings, const std::string& models_dir) {
  if (spec == "none") return nullptr;
  if (spec == "dnn") {
    return std::make_unique<DnnSegmenter>(DnnOptionsFromSettings(settings, models_dir));
  }
  if (spec == "maskrcnn") {
    return std::make_unique<MaskRcnnSegmenter>(MaskRcnnOptionsFromSettings(settings, models_dir));
  }
  if (spec.rfind("masks:", 0) == 0) {
    const std::string dir = spec.substr(6);
    if (dir.empty()) throw InputError("segmenter 'masks:DIR' needs a folder after 'masks:'");
    return std::make_unique<MaskDirSegmenter>(dir, "masks");
  }
  if (spec == "gt") {
    const std::string dir = (std::filesystem::path(dataset_dir) / "masks").string();
    if (!std::filesystem::is_directory(dir)) {
      throw InputError(dir, 0,
                       "no masks folder: gt masks only exist for synthetic sequences "
                       "(detslam synth); use --segmenter dnn or masks:DIR");
    }
    return std::make_unique<MaskDirSegmenter>(dir, "gt");
  }
  throw InputError("unknown segmenter '" + spec +
                   "' (expected dnn, maskrcnn, masks:DIR, gt or none)");
}

}  // namespace detslam
