#include "detslam/io/settings.h"

#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

#include "detslam/core/atomic_file.h"
#include "detslam/core/check.h"
#include "detslam/io/setting_spec.h"

namespace detslam {
namespace {

// ---- reading ----

struct Entry {
  std::string text;
  int line = 0;  // 1-based
};
using Entries = std::map<std::string, Entry>;

// Flattens nested maps into dotted keys; OpenCV matrices and sequences are not scalar settings and
// are skipped.
void Flatten(const std::string& path, const YAML::Node& node, const std::string& prefix,
             Entries* entries) {
  for (const auto& kv : node) {
    const std::string key = prefix + kv.first.as<std::string>();
    const YAML::Node& value = kv.second;
    const int line = value.Mark().line + 1;
    if (value.IsScalar()) {
      (*entries)[key] = {value.Scalar(), line};
    } else if (value.IsMap() && value.Tag().find("opencv-matrix") == std::string::npos) {
      Flatten(path, value, key + ".", entries);
    } else if (value.IsNull()) {
      spdlog::warn("{}:{}: key '{}' has no value; ignored", path, line, key);
    } else {
      spdlog::debug("{}:{}: non-scalar key '{}' ignored", path, line, key);
    }
  }
}

class Reader {
 public:
  Reader(std::string path, Entries entries)
      : path_(std::move(path)), entries_(std::move(entries)) {}

  bool Has(const std::string& key) const { return entries_.count(key) > 0; }

  double Double(const std::string& key, double fallback, bool required = false) {
    const Entry* e = Find(key, required);
    if (e == nullptr) return fallback;
    double v = 0;
    if (!ParseDoubleText(e->text, &v)) Wrong(*e, key, "a finite number");
    return v;
  }
  int Int(const std::string& key, int fallback, bool required = false) {
    const Entry* e = Find(key, required);
    if (e == nullptr) return fallback;
    int v = 0;
    if (!ParseIntText(e->text, &v)) Wrong(*e, key, "an integer");
    return v;
  }
  bool Bool(const std::string& key, bool fallback) {
    const Entry* e = Find(key, false);
    if (e == nullptr) return fallback;
    bool v = false;
    if (!ParseBoolText(e->text, &v)) Wrong(*e, key, "a boolean (0/1, true/false)");
    return v;
  }
  std::string String(const std::string& key, const std::string& fallback) {
    const Entry* e = Find(key, false);
    return e == nullptr ? fallback : e->text;
  }

  // Scalar keys that no typed accessor consumed, into `extra` and `extra_origin` ("FILE:LINE").
  void MoveUnused(Settings* s) const {
    for (const auto& [key, entry] : entries_) {
      if (used_.count(key) > 0) continue;
      s->extra[key] = entry.text;
      s->extra_origin[key] = path_ + ":" + std::to_string(entry.line);
    }
  }

 private:
  const Entry* Find(const std::string& key, bool required) {
    used_.insert(key);
    auto it = entries_.find(key);
    if (it == entries_.end()) {
      if (required) throw InputError(path_, 0, "missing required key '" + key + "'");
      return nullptr;
    }
    return &it->second;
  }
  [[noreturn]] void Wrong(const Entry& e, const std::string& key, const std::string& expected) {
    throw InputError(path_, e.line,
                     "key '" + key + "' must be " + expected + ", got '" + e.text + "'");
  }

  std::string path_;
  Entries entries_;
  std::set<std::string> used_;
};

Entries LoadEntries(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, 0, "cannot open settings file (missing or unreadable)");
  std::stringstream buffer;
  buffer << in.rdbuf();
  std::string text = buffer.str();
  // OpenCV FileStorage writes the directive as "%YAML:1.0", which is not valid YAML directive
  // syntax; turn it into a comment (keeps line numbers).
  size_t pos = 0;
  while (pos < text.size()) {
    const size_t eol = text.find('\n', pos);
    size_t end = eol == std::string::npos ? text.size() : eol;
    const std::string line = text.substr(pos, end - pos);
    const size_t first = line.find_first_not_of(" \t\r");
    const bool blank_or_comment = first == std::string::npos || line[first] == '#';
    if (line.rfind("%YAML", 0) == 0) {
      text.insert(pos, "#");
      ++end;
    } else if (!blank_or_comment && line[0] != '%') {
      break;  // directives only come before the first content line
    }
    if (eol == std::string::npos) break;
    pos = end + 1;
  }
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(path, e.mark.line + 1, "YAML syntax error: " + e.msg);
  }
  if (root.IsNull()) throw InputError(path, 0, "settings file is empty");
  if (!root.IsMap()) throw InputError(path, 0, "settings file must be a map of 'key: value'");
  Entries entries;
  try {
    Flatten(path, root, "", &entries);
  } catch (const YAML::Exception& e) {  // e.g. a key that is itself a map or a sequence
    throw InputError(path, e.mark.line + 1, "unsupported YAML structure: " + e.msg);
  }
  return entries;
}

// ---- writing ----

// Shortest text that reads back to the same double, always with a decimal point so that OpenCV
// FileStorage (and ORB-SLAM3's real-valued reads) see a real.
std::string FormatReal(double v) {
  char buf[64];
  for (int precision = 15; precision <= 17; ++precision) {
    std::snprintf(buf, sizeof(buf), "%.*g", precision, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  std::string s(buf);
  if (s.find_first_of(".na") != std::string::npos) return s;  // has a point, or nan/inf
  const size_t e = s.find('e');
  if (e == std::string::npos) return s + ".0";
  return s.substr(0, e) + ".0" + s.substr(e);
}

std::string Quote(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out.push_back('\\');
    out.push_back(c);
  }
  return out + "\"";
}

bool IsPlainKey(const std::string& key) {
  if (key.empty() || !(std::isalpha(static_cast<unsigned char>(key[0])) || key[0] == '_')) {
    return false;
  }
  return std::all_of(key.begin(), key.end(), [](unsigned char c) {
    return std::isalnum(c) || c == '_' || c == '.' || c == '-';
  });
}

// Numbers stay bare (typed the same on read-back), everything else is quoted.
std::string FormatExtraValue(const std::string& value) {
  double d = 0;
  if (ParseDoubleText(value, &d) &&
      value.find_first_not_of("0123456789+-.eE") == std::string::npos) {
    return value;
  }
  return Quote(value);
}

}  // namespace

bool OrbSettings::Check(std::string* error) const {
  std::ostringstream os;
  if (n_features <= 0) os << "ORBextractor.nFeatures must be positive; ";
  if (!(scale_factor > 1.0)) os << "ORBextractor.scaleFactor must be > 1; ";
  if (n_levels <= 0) os << "ORBextractor.nLevels must be positive; ";
  if (ini_th_fast <= 0 || min_th_fast <= 0) os << "FAST thresholds must be positive; ";
  if (min_th_fast > ini_th_fast) os << "ORBextractor.minThFAST must not exceed iniThFAST; ";
  if (error != nullptr) *error = os.str();
  return os.str().empty();
}

Settings ReadSettings(const std::string& path) {
  Reader r(path, LoadEntries(path));
  Settings s;
  s.source = path;
  PinholeCamera& c = s.camera;
  const bool v1 = r.Has("File.version");
  if (v1) {
    const std::string version = r.String("File.version", "");
    if (version != "1.0") {
      throw InputError(path, 0, "unsupported File.version '" + version + "' (expected \"1.0\")");
    }
    const std::string type = r.String("Camera.type", "PinHole");
    if (type != "PinHole") {
      throw InputError(path, 0, "Camera.type '" + type + "' is not supported (only PinHole)");
    }
  }
  const std::string cam = v1 ? "Camera1." : "Camera.";
  c.fx = r.Double(cam + "fx", c.fx, true);
  c.fy = r.Double(cam + "fy", c.fy, true);
  c.cx = r.Double(cam + "cx", c.cx, true);
  c.cy = r.Double(cam + "cy", c.cy, true);
  c.k1 = r.Double(cam + "k1", 0.0);
  c.k2 = r.Double(cam + "k2", 0.0);
  c.p1 = r.Double(cam + "p1", 0.0);
  c.p2 = r.Double(cam + "p2", 0.0);
  c.k3 = r.Double(cam + "k3", 0.0);
  c.width = r.Int("Camera.width", c.width, true);
  c.height = r.Int("Camera.height", c.height, true);
  c.fps = r.Double("Camera.fps", c.fps);
  c.rgb_order = r.Bool("Camera.RGB", c.rgb_order);
  c.rolling_shutter_readout = r.Double("Camera.RollingShutterReadout", c.rolling_shutter_readout);
  if (v1) {
    if (r.Has("Stereo.b")) c.bf = r.Double("Stereo.b", 0.0) * c.fx;
    c.th_depth = r.Double("Stereo.ThDepth", c.th_depth);
    c.depth_map_factor = r.Double("RGBD.DepthMapFactor", c.depth_map_factor);
    c.disparity_sigma = r.Double("RGBD.DisparitySigma", c.disparity_sigma);
  } else {
    c.bf = r.Double("Camera.bf", c.bf);
    c.th_depth = r.Double("ThDepth", c.th_depth);
    c.depth_map_factor = r.Double("DepthMapFactor", c.depth_map_factor);
    // detslam's own key, in either spelling (its v1.0 name is the one `settings --list` shows).
    c.disparity_sigma = r.Double("DisparitySigma", r.Double("RGBD.DisparitySigma", c.disparity_sigma));
  }
  OrbSettings& o = s.orb;
  o.n_features = r.Int("ORBextractor.nFeatures", o.n_features);
  o.scale_factor = r.Double("ORBextractor.scaleFactor", o.scale_factor);
  o.n_levels = r.Int("ORBextractor.nLevels", o.n_levels);
  o.ini_th_fast = r.Int("ORBextractor.iniThFAST", o.ini_th_fast);
  o.min_th_fast = r.Int("ORBextractor.minThFAST", o.min_th_fast);
  r.MoveUnused(&s);

  std::string error;
  if (!c.Check(&error)) throw InputError(path, 0, "invalid camera settings: " + error);
  if (!o.Check(&error)) throw InputError(path, 0, "invalid ORB settings: " + error);
  spdlog::debug("{}: read {}-style settings, {} extra keys", path, v1 ? "v1.0" : "old",
                s.extra.size());
  return s;
}

void WriteSettings(const std::string& path, const Settings& settings) {
  const PinholeCamera& c = settings.camera;
  const OrbSettings& o = settings.orb;
  std::vector<std::pair<std::string, std::string>> lines = {
      {"File.version", "\"1.0\""},
      {"Camera.type", "\"PinHole\""},
      {"Camera1.fx", FormatReal(c.fx)},
      {"Camera1.fy", FormatReal(c.fy)},
      {"Camera1.cx", FormatReal(c.cx)},
      {"Camera1.cy", FormatReal(c.cy)},
      {"Camera1.k1", FormatReal(c.k1)},
      {"Camera1.k2", FormatReal(c.k2)},
      {"Camera1.p1", FormatReal(c.p1)},
      {"Camera1.p2", FormatReal(c.p2)},
      {"Camera1.k3", FormatReal(c.k3)},
      {"Camera.width", std::to_string(c.width)},
      {"Camera.height", std::to_string(c.height)},
      // ORB-SLAM3 v1.0 reads the frame rate as an integer.
      {"Camera.fps",
       c.fps == std::round(c.fps) ? std::to_string(std::lround(c.fps)) : FormatReal(c.fps)},
      {"Camera.RGB", c.rgb_order ? "1" : "0"},
      {"Stereo.ThDepth", FormatReal(c.th_depth)},
      {"Stereo.b", FormatReal(c.bf / c.fx)},
      {"RGBD.DepthMapFactor", FormatReal(c.depth_map_factor)},
      {"RGBD.DisparitySigma", FormatReal(c.disparity_sigma)},
      {"ORBextractor.nFeatures", std::to_string(o.n_features)},
      {"ORBextractor.scaleFactor", FormatReal(o.scale_factor)},
      {"ORBextractor.nLevels", std::to_string(o.n_levels)},
      {"ORBextractor.iniThFAST", std::to_string(o.ini_th_fast)},
      {"ORBextractor.minThFAST", std::to_string(o.min_th_fast)},
  };
  // detslam's own camera key, written only for a rolling shutter (ORB-SLAM3 ignores it).
  if (c.rolling_shutter_readout > 0) {
    const auto rgb = std::find_if(lines.begin(), lines.end(),
                                  [](const auto& kv) { return kv.first == "Camera.RGB"; });
    lines.insert(rgb + 1, {"Camera.RollingShutterReadout", FormatReal(c.rolling_shutter_readout)});
  }
  std::set<std::string> written;
  for (const auto& kv : lines) written.insert(kv.first);
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "%YAML:1.0\n---\n";
    out << "# detslam settings (ORB-SLAM3 v1.0 key style)";
    if (!settings.source.empty()) out << ", from " << settings.source;
    out << "\n";
    for (const auto& [key, value] : lines) out << key << ": " << value << "\n";
    bool header = false;
    for (const auto& [key, value] : settings.extra) {
      if (written.count(key) > 0) {
        spdlog::warn("{}: extra key '{}' clashes with a written camera/ORB key; skipped", path,
                     key);
        continue;
      }
      if (!header) out << "\n# other settings\n";
      header = true;
      out << (IsPlainKey(key) ? key : Quote(key)) << ": " << FormatExtraValue(value) << "\n";
    }
  });
}

void ApplySettingOverrides(const std::vector<std::string>& overrides, Settings* settings) {
  for (const std::string& o : overrides) {
    const size_t eq = o.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == o.size()) {
      throw InputError("--set " + o + ": expected KEY=VALUE, e.g. --set Dynamic.Alpha=0.2");
    }
    const std::string key = o.substr(0, eq);
    if (key == "RGBD.DisparitySigma") {  // a weighting of the depth, not a calibration
      double sigma = -1;
      if (!ParseDoubleText(o.substr(eq + 1), &sigma) || !(sigma >= 0)) {
        throw InputError("--set " + o + ": RGBD.DisparitySigma must be a number >= 0");
      }
      settings->camera.disparity_sigma = sigma;
      continue;
    }
    for (const char* typed : {"Camera", "Camera1.", "Camera.", "Stereo.", "RGBD.", "ORBextractor."}) {
      if (key.rfind(typed, 0) == 0) {
        throw InputError("--set " + o + ": camera and ORB keys come from the settings file (--config)");
      }
    }
    settings->extra[key] = o.substr(eq + 1);
    settings->extra_origin[key] = "--set " + o;
  }
  // The source names every override, so run.json records how the run was configured.
  for (const std::string& o : overrides) settings->source += " + --set " + o;
}

}  // namespace detslam
