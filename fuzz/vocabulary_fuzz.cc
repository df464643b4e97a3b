// Fuzz target: vocabulary files (Vocabulary::Load). The first byte chooses whether the rest is
// the file as it is or a body closed by a valid checksum (to reach the parsing behind it); an
// accepted vocabulary then turns descriptors made of the input's bytes into words.
#include <opencv2/core.hpp>

#include "detslam/place/vocabulary.h"
#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace detslam;
  std::string bytes;
  if (!fuzz::BinaryFile(data, size, &bytes)) return 0;
  const std::string path = fuzz::WriteInput("vocabulary.dslvoc", bytes);
  Vocabulary v;
  if (!fuzz::Accepts([&] { v.Load(path); }) || v.empty()) return 0;
  cv::Mat descriptors(4, 32, CV_8UC1);
  for (int i = 0; i < 4 * 32; ++i) descriptors.data[i] = data[static_cast<size_t>(i) % size];
  FeatureVector features;
  fuzz::Accepts([&] { v.Transform(descriptors, &features, 2); });
  return 0;
}
