// The 80 COCO detection class names in the order of the usual 80-class models (YOLOX, YOLO,
// Yolo-Fastest; person = 0), used to give every instance a COCO class id whatever its source.
#pragma once

#include <string>
#include <vector>

namespace detslam {

// Names in class-id order ("person", "bicycle", ..., "toothbrush"); spaces kept ("traffic light").
const std::vector<std::string>& CocoClassNames();

// Class id of a COCO name (exact, case-sensitive), -1 if unknown. "body" (the person-only
// Yolo-Fastest model's label) maps to 0, person.
int CocoClassId(const std::string& name);

}  // namespace detslam
