// Fuzz target: map files (ReadMapFileInfo, LoadMapFile). The first byte chooses whether the rest
// is the file as it is or a body closed by a valid checksum; the map is then loaded with the
// camera, pyramid and vocabulary checksum its own header names, so the fuzzer reaches the
// keyframes, map points, covisibility and spanning tree behind the header checks.
#include "detslam/map/map_file.h"
#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace detslam;
  std::string bytes;
  if (!fuzz::BinaryFile(data, size, &bytes)) return 0;
  const std::string path = fuzz::WriteInput("map.dslmap", bytes);
  MapFileInfo info;
  if (!fuzz::Accepts([&] { info = ReadMapFileInfo(path); })) return 0;
  MapFileExpectation expected;
  expected.camera = info.camera;
  if (!fuzz::Accepts([&] { expected.scale = ScaleInfo::Geometric(info.scale_factor, info.levels); }))
    return 0;
  expected.vocabulary_checksum = info.vocabulary_checksum;
  fuzz::Accepts([&] { LoadMapFile(path, expected, &info); });
  return 0;
}
