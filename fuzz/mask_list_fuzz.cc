// Fuzz target: a mask folder's instances.txt (ReadInstanceList, both field layouts).
#include "detslam/segmentation/mask_dir.h"
#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace detslam;
  const std::string path = fuzz::WriteInput("instances.txt", fuzz::Bytes(data, size));
  fuzz::Accepts([&] { ReadInstanceList(path); });
  return 0;
}
