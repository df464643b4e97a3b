#include "detslam/io/rgbd_source.h"

namespace detslam {

std::string ImageSizeText(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

}  // namespace detslam
