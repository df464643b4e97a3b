#include "detslam/dynamic/instance_memory.h"

namespace detslam {
namespace {

double BoxIouOf(const cv::Rect& a, const cv::Rect& b) {
  const double inter = (a & b).area();
  const double uni = a.area() + b.area() - inter;
  return uni > 0 ? inter / uni : 0.0;
}

}  // namespace

std::vector<Instance> InstanceMemory::Update(const std::vector<Instance>& current) {
  std::vector<Instance> out = current;
  std::vector<Remembered> next;
  for (const Instance& inst : current) next.push_back({inst, 0});
  if (max_age_ > 0) {
    for (const Remembered& r : remembered_) {
      bool covered = false;
      for (const Instance& c : current) {
        if (c.class_name == r.instance.class_name && BoxIouOf(c.box, r.instance.box) >= min_iou_)
          covered = true;
      }
      if (covered || r.age + 1 > max_age_) continue;
      out.push_back(r.instance);
      next.push_back({r.instance, r.age + 1});
    }
  }
  remembered_ = std::move(next);
  return out;
}

}  // namespace detslam
