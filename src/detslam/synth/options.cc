#include "detslam/synth/options.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "detslam/core/check.h"
#include "detslam/core/math.h"

namespace detslam {

const std::vector<std::string>& SynthPresetNames() {
  static const std::vector<std::string> kNames = {
      "static",         "walking_xyz", "walking_static", "walking_rpy", "walking_halfsphere",
      "sitting_static", "loop",        "loop_long",      "lookalike",   "roam"};
  return kNames;
}

bool IsSynthPreset(const std::string& name) {
  const auto& names = SynthPresetNames();
  return std::find(names.begin(), names.end(), name) != names.end();
}

namespace {
std::string ValidPresetList() {
  std::string out;
  for (const auto& n : SynthPresetNames()) out += (out.empty() ? "" : ", ") + n;
  return out;
}
}  // namespace

void RequireSynthPreset(const std::string& preset) {
  if (!IsSynthPreset(preset)) {
    throw InputError("unknown synth preset '" + preset + "' (valid: " + ValidPresetList() + ")");
  }
}

int SynthPresetDefaultFrames(const std::string& preset) {
  RequireSynthPreset(preset);
  if (preset == "loop") return 900;
  if (preset == "loop_long") return 2010;  // one 64 s lap, then 3 s over its start again
  if (preset == "lookalike") return 1350;  // 45 s: first part, passage, second part
  if (preset == "walking_halfsphere") return 900;
  if (preset == "roam") return 900;  // 30 s: front, turn, back of the room, turn on, front
  if (preset == "walking_static" || preset == "sitting_static") return 700;
  return 800;
}

int SynthFrameCount(const SynthOptions& options) {
  return options.frames > 0 ? options.frames : SynthPresetDefaultFrames(options.preset);
}

bool SynthOptions::Check(std::string* error) const {
  std::ostringstream os;
  if (!IsSynthPreset(preset)) {
    os << "unknown preset '" << preset << "' (valid: " << ValidPresetList() << "); ";
  }
  if (frames == 0 || frames > 100000) os << "frames must be in 1..100000 or negative (default); ";
  if (!(std::abs(depth_scale_bias) <= kMaxDepthScaleBias)) {
    os << "--depth-scale-bias must be a number in [" << -kMaxDepthScaleBias << ", "
       << kMaxDepthScaleBias << "] (got " << depth_scale_bias << "); ";
  }
  if (cut_begin != 0 || cut_end != 0) {
    // The frame count is only known for a valid preset.
    const int n =
        IsSynthPreset(preset) && frames != 0 && frames <= 100000 ? SynthFrameCount(*this) : -1;
    if (cut_begin < 1 || cut_end <= cut_begin || (n > 0 && cut_end >= n)) {
      os << "--cut " << cut_begin << ":" << cut_end << " must satisfy 1 <= A < B <= frames - 1";
      if (n > 0) os << " = " << n - 1;
      os << " (at least one frame before and after the cut); ";
    }
  }
  if (cover_start_s != 0.0 || cover_seconds != 0.0) {
    const int n =
        IsSynthPreset(preset) && frames != 0 && frames <= 100000 ? SynthFrameCount(*this) : -1;
    const double duration = n > 0 ? n / 30.0 : -1;
    if (!(cover_start_s > 0) || !(cover_seconds > 0) ||
        (duration > 0 && !(cover_start_s + cover_seconds < duration))) {
      os << "--cover " << cover_start_s << ":" << cover_seconds
         << " must start after the first frame and end before the last";
      if (duration > 0) os << " (the sequence lasts " << duration << " s)";
      os << "; ";
    }
  }
  if (!realism_off.empty() && realism != SynthRealism::kRealistic)
    os << "--realism-off needs --realism realistic; ";
  if (error != nullptr) *error = os.str();
  return os.str().empty();
}

const std::vector<std::string>& SynthRealismEffects() {
  static const std::vector<std::string> kEffects = {"timing", "shutter",      "blur",
                                                    "colour", "quantisation", "noise",
                                                    "distortion", "dropouts", "rooms",
                                                    "people"};
  return kEffects;
}

bool SynthOptions::RealismOff(const std::string& effect) const {
  return std::find(realism_off.begin(), realism_off.end(), effect) != realism_off.end();
}

void ParseSynthRealismOff(const std::string& text, SynthOptions* options) {
  const auto& valid = SynthRealismEffects();
  std::vector<std::string> out;
  size_t start = 0;
  while (start <= text.size()) {
    const size_t comma = std::min(text.find(',', start), text.size());
    const std::string name = text.substr(start, comma - start);
    if (std::find(valid.begin(), valid.end(), name) == valid.end()) {
      std::string list;
      for (const auto& v : valid) list += (list.empty() ? "" : ", ") + v;
      throw InputError("--realism-off '" + text + "': unknown effect '" + name + "' (valid: " +
                       list + ")");
    }
    if (std::find(out.begin(), out.end(), name) == out.end()) out.push_back(name);
    start = comma + 1;
  }
  options->realism_off = out;
}

const char* SynthRealismName(SynthRealism realism) {
  return realism == SynthRealism::kRealistic ? "realistic" : "easy";
}

SynthRealism ParseSynthRealism(const std::string& text) {
  if (text == "easy") return SynthRealism::kEasy;
  if (text == "realistic") return SynthRealism::kRealistic;
  throw InputError("--realism '" + text + "': unknown (valid: realistic, easy)");
}

bool SynthOptions::Covered(int k) const {
  const double t = k / 30.0;
  return HasCover() && t >= cover_start_s && t < cover_start_s + cover_seconds;
}

void ParseSynthCover(const std::string& text, SynthOptions* options) {
  const auto bad = [&](const std::string& why) {
    return InputError("--cover '" + text + "': " + why +
                      " (expected START:SECONDS, seconds from the first frame, SECONDS > 0)");
  };
  const size_t colon = text.find(':');
  if (colon == std::string::npos || text.find(':', colon + 1) != std::string::npos)
    throw bad("needs exactly one ':'");
  const auto parse = [&](const std::string& part) {
    size_t used = 0;
    double v = 0;
    try {
      v = std::stod(part, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (part.empty() || used != part.size() || !std::isfinite(v) || v < 0)
      throw bad("'" + part + "' is not a non-negative number of seconds");
    return v;
  };
  const double start = parse(text.substr(0, colon)), seconds = parse(text.substr(colon + 1));
  if (!(seconds > 0)) throw bad("SECONDS must be positive");
  options->cover_start_s = start;
  options->cover_seconds = seconds;
}

void ParseSynthCut(const std::string& text, SynthOptions* options) {
  const auto bad = [&](const std::string& why) {
    return InputError("--cut '" + text + "': " + why + " (expected A:B, frame indices, A < B)");
  };
  const size_t colon = text.find(':');
  if (colon == std::string::npos || text.find(':', colon + 1) != std::string::npos) {
    throw bad("needs exactly one ':'");
  }
  const auto parse = [&](const std::string& part) {
    if (part.empty() || part.size() > 9 ||
        !std::all_of(part.begin(), part.end(), [](char c) { return c >= '0' && c <= '9'; })) {
      throw bad("'" + part + "' is not a frame index");
    }
    return std::stoi(part);
  };
  const int a = parse(text.substr(0, colon)), b = parse(text.substr(colon + 1));
  if (a >= b) throw bad("A must be less than B");
  options->cut_begin = a;
  options->cut_end = b;
}

double SynthDepthScale(double bias, int k, int frames) {
  if (bias == 0.0 || frames < 2) return 1.0;
  const double s = std::sin(kPi * static_cast<double>(k) / (frames - 1));
  return 1.0 + bias * s * s;
}

}  // namespace detslam
