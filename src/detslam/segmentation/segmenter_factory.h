// Builds a segmenter from the command line's --segmenter value.
#pragma once

#include <memory>
#include <string>

#include "detslam/segmentation/segmenter.h"
#include "detslam/segmentation/segmenter_settings.h"

namespace detslam {

// spec:
//   "dnn"        DnnSegmenter with DnnOptionsFromSettings(settings, models_dir)
//   "maskrcnn"   MaskRcnnSegmenter with MaskRcnnOptionsFromSettings (untested: no weights here)
//   "masks:DIR"  MaskDirSegmenter reading DIR (mask_dir.h format)
//   "gt"         MaskDirSegmenter on <dataset_dir>/masks (synthetic sequences' ground truth)
//   "none"       nullptr (no segmentation)
// Throws InputError for an unknown spec, a missing folder or missing models.
std::unique_ptr<Segmenter> MakeSegmenter(const std::string& spec, const std::string& dataset_dir,
                                         const SegmenterSettings& settings, const std::string& models_dir);

}  // namespace detslam
