// Carries dynamic instances forward for a few frames when the detector loses them (a person the
// detector misses for a frame or two is still moving): an instance of the previous frames that no
// current instance overlaps (box IoU below `min_iou`) is re-used, box and mask unchanged, for at
// most `max_age` frames. Frames must be fed in order.
#pragma once

#include <vector>

#include "detslam/segmentation/segmenter.h"

namespace detslam {

class InstanceMemory {
 public:
  InstanceMemory(int max_age, double min_iou = 0.3) : max_age_(max_age), min_iou_(min_iou) {}

  // Returns `current` plus remembered instances that are not covered by it.
  std::vector<Instance> Update(const std::vector<Instance>& current);

 private:
  struct Remembered {
    Instance instance;
    int age = 0;
  };
  int max_age_;
  double min_iou_;
  std::vector<Remembered> remembered_;
};

}  // namespace detslam
