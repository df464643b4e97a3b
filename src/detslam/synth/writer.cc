#include "detslam/synth/writer.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <filesystem>
#include <opencv2/core/utility.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "detslam/core/atomic_file.h"
#include "detslam/core/check.h"
#include "detslam/io/settings.h"
#include "detslam/io/trajectory.h"
#include "detslam/synth/sequence.h"

namespace detslam {
namespace {

using Clock = std::chrono::steady_clock;

double Since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// zlib level 1 for all; colour images with zlib's run-length strategy, which on the sensor-noisy
// colour frames gives smaller files (about 12 %) in about half the encoding time and decodes
// faster; the 16-bit depth and mask images keep the default strategy (smaller for them).
std::string EncodePng(const cv::Mat& image, const std::string& what) {
  std::vector<uchar> buf;
  std::vector<int> params = {cv::IMWRITE_PNG_COMPRESSION, 1};
  if (image.depth() == CV_8U) params.insert(params.end(), {cv::IMWRITE_PNG_STRATEGY, cv::IMWRITE_PNG_STRATEGY_RLE});
  if (!cv::imencode(".png", image, buf, params)) {
    throw InputError("cannot encode " + what + " as PNG");
  }
  return std::string(buf.begin(), buf.end());
}

std::string Describe(const SynthOptions& o) {
  std::ostringstream os;
  os << "detslam synth --preset " << o.preset << " --seed " << o.seed;
  if (!o.people) os << " --no-people";
  if (!o.people_dir.empty()) os << " --people " << o.people_dir;
  if (o.motion_blur) os << " --blur";
  if (o.realism != SynthRealism::kEasy) os << " --realism " << SynthRealismName(o.realism);
  for (size_t i = 0; i < o.realism_off.size(); ++i)
    os << (i == 0 ? " --realism-off " : ",") << o.realism_off[i];
  if (o.depth_scale_bias != 0.0) os << " --depth-scale-bias " << o.depth_scale_bias;
  if (o.HasCut()) os << " --cut " << o.cut_begin << ":" << o.cut_end;
  if (o.HasCover()) os << " --cover " << o.cover_start_s << ":" << o.cover_seconds;
  return os.str();
}

void WriteSynthSettings(const std::string& path, const PinholeCamera& camera) {
  Settings s;
  s.camera = camera;
  s.orb = OrbSettings{};  // nFeatures 1000, scaleFactor 1.2, nLevels 8, FAST 20 / 7
  s.source = "detslam synth";
  WriteSettings(path, s);
}

}  // namespace

int CountFastCorners(const cv::Mat& bgr) {
  cv::Mat gray;
  cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
  std::vector<cv::KeyPoint> kps;
  cv::FAST(gray, kps, 20, true);
  return static_cast<int>(kps.size());
}

double MissingDepthFraction(const cv::Mat& depth) {
  CV_Assert(depth.channels() == 1 && !depth.empty());
  return 1.0 - static_cast<double>(cv::countNonZero(depth)) / static_cast<double>(depth.total());
}

SynthStats WriteSequence(const SynthOptions& options, const std::string& out_dir) {
  namespace fs = std::filesystem;
  const auto start = Clock::now();
  SyntheticSequence seq(options);  // validates options, loads people
  std::error_code ec;
  for (const char* sub : {"rgb", "depth", "masks"}) {
    fs::create_directories(fs::path(out_dir) / sub, ec);
    if (ec)
      throw InputError(out_dir, 0,
                       std::string("cannot create folder ") + sub + ": " + ec.message());
  }
  const std::string header = Describe(options);
  std::ostringstream rgb_txt, depth_txt, inst_txt;
  rgb_txt << "# color images\n# file: '" << header << "'\n# timestamp filename\n";
  depth_txt << "# depth maps\n# file: '" << header << "'\n# timestamp filename\n";
  inst_txt
      << "# moving-object instances per frame (ground truth of the synthetic sequence)\n"
      << "# file: '" << header << "'\n"
      << "# timestamp id class score x y w h\n"
      << "# timestamp: colour image stamp; id: value of the object's pixels in\n"
      << "# masks/<timestamp>.png (16-bit, 0 = static scene); class: COCO name; score: 1 (truth);\n"
      << "# x y w h: bounding box of the visible pixels (pixels, top-left origin)\n";
  Trajectory gt;
  SynthStats stats;
  double coverage_sum = 0, fast_sum = 0, missing_sum = 0;
  for (int k = 0; k < seq.size(); ++k) {
    // --cut: the camera keeps moving through the cut frames, none of their files are written.
    if (options.HasCut() && k >= options.cut_begin && k < options.cut_end) continue;
    ++stats.frames;
    const auto t0 = Clock::now();
    const SynthFrame f = seq.Render(k);
    stats.render_seconds += Since(t0);
    const std::string stamp = f.stamp.ToString(), dstamp = f.depth_stamp.ToString();
    const std::string names[3] = {"rgb/" + stamp + ".png", "depth/" + dstamp + ".png",
                                  "masks/" + stamp + ".png"};
    const cv::Mat* images[3] = {&f.bgr, &f.depth16, &f.instance_mask};
    std::string bytes[3];
    cv::parallel_for_(cv::Range(0, 3), [&](const cv::Range& r) {
      for (int i = r.start; i < r.end; ++i) bytes[i] = EncodePng(*images[i], names[i]);
    });
    for (int i = 0; i < 3; ++i)
      WriteBytesAtomically((fs::path(out_dir) / names[i]).string(), bytes[i]);
    rgb_txt << stamp << " " << names[0] << "\n";
    depth_txt << dstamp << " " << names[1] << "\n";
    for (const SynthInstance& in : f.instances) {
      inst_txt << stamp << " " << in.id << " " << in.label << " " << in.score << " " << in.box.x
               << " " << in.box.y << " " << in.box.width << " " << in.box.height << "\n";
    }
    gt.push_back({f.stamp, f.world_from_cam});
    coverage_sum += f.Coverage();
    const auto measure_start = Clock::now();
    if (k % 5 == 0) {
      fast_sum += CountFastCorners(f.bgr);
      missing_sum += MissingDepthFraction(f.depth16);
      ++stats.sampled_frames;
    }
    const double measure = Since(measure_start);
    stats.total_seconds -= measure;  // statistics are not part of the generator's speed
    if ((k + 1) % 50 == 0 || k + 1 == seq.size()) {
      spdlog::info("synth {}: frame {}/{} ({:.1f} fps)", options.preset, k + 1, seq.size(),
                   stats.frames / std::max(1e-9, Since(start) + stats.total_seconds));
    }
  }
  auto write_text = [&](const std::string& name, const std::string& text) {
    WriteFileAtomically((fs::path(out_dir) / name).string(), [&](std::ostream& os) { os << text; });
  };
  write_text("rgb.txt", rgb_txt.str());
  write_text("depth.txt", depth_txt.str());
  write_text("masks/instances.txt", inst_txt.str());
  WriteTumTrajectory((fs::path(out_dir) / "groundtruth.txt").string(), gt,
                     "ground truth trajectory (world_from_camera)\nfile: '" + header + "'");
  WriteSynthSettings((fs::path(out_dir) / "settings.yaml").string(), seq.camera());
  stats.total_seconds += Since(start);
  stats.render_fps = stats.frames / std::max(1e-9, stats.render_seconds);
  stats.total_fps = stats.frames / std::max(1e-9, stats.total_seconds);
  stats.mean_coverage = coverage_sum / std::max(1, stats.frames);
  stats.mean_fast_corners = fast_sum / std::max(1, stats.sampled_frames);
  stats.mean_missing_depth = missing_sum / std::max(1, stats.sampled_frames);
  spdlog::info("synth {}: wrote {} frames to {} (render {:.1f} fps, total {:.1f} fps)",
               options.preset, stats.frames, out_dir, stats.render_fps, stats.total_fps);
  return stats;
}

}  // namespace detslam
