// Fuzz target: a dataset folder's lists (rgb.txt, depth.txt, groundtruth.txt and an association
// file), one input holding the four separated by "\n===\n" (RgbdDataset::Open). The folder holds
// the images a.png, b.png, rgb/1.png and depth/1.png (empty files: only the lists are parsed).
#include "detslam/io/dataset.h"
#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace detslam;
  namespace fs = std::filesystem;
  const fs::path dir = fuzz::WorkDir() / "dataset";
  static const bool made = [&] {
    fs::create_directories(dir / "rgb");
    fs::create_directories(dir / "depth");
    for (const char* f : {"a.png", "b.png", "rgb/1.png", "depth/1.png"}) std::ofstream(dir / f);
    return true;
  }();
  (void)made;
  const std::vector<std::string> parts = fuzz::SplitParts(fuzz::Bytes(data, size));
  const char* names[] = {"rgb.txt", "depth.txt", "groundtruth.txt", "associations.txt"};
  for (size_t i = 0; i < 4; ++i) {
    if (i < parts.size()) {
      fuzz::WriteInput("dataset/" + std::string(names[i]), parts[i]);
    } else {
      fs::remove(dir / names[i]);
    }
  }
  DatasetOptions options;
  if (parts.size() > 3) options.association_file = (dir / "associations.txt").string();
  fuzz::Accepts([&] {
    const RgbdDataset d = RgbdDataset::Open(dir.string(), options);
    for (size_t i = 0; i < d.size(); ++i) (void)d.frame(i);
  });
  return 0;
}
