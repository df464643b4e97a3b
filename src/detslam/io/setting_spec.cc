#include "detslam/io/setting_spec.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <sstream>

namespace detslam {
namespace {

std::string Trimmed(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t"), b = s.find_last_not_of(" \t");
  return a == std::string::npos ? "" : s.substr(a, b - a + 1);
}

std::string FormatNumber(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  std::ostringstream os;
  os << v;
  return os.str();
}

}  // namespace

const char* ToString(SettingType type) {
  switch (type) {
    case SettingType::kBool:
      return "bool";
    case SettingType::kInt:
      return "int";
    case SettingType::kDouble:
      return "double";
    case SettingType::kString:
      return "string";
    case SettingType::kList:
      return "list";
  }
  return "?";
}

bool ParseDoubleText(const std::string& text, double* out) {
  if (text.empty()) return false;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0' || !std::isfinite(v)) return false;
  *out = v;
  return true;
}

bool ParseIntText(const std::string& text, int* out) {
  double v = 0;
  if (!ParseDoubleText(text, &v) || v != std::floor(v) || v < std::numeric_limits<int>::min() ||
      v > std::numeric_limits<int>::max()) {
    return false;
  }
  *out = static_cast<int>(v);
  return true;
}

bool ParseBoolText(const std::string& text, bool* out) {
  std::string t = text;
  std::transform(t.begin(), t.end(), t.begin(), [](unsigned char c) { return std::tolower(c); });
  if (t == "1" || t == "true" || t == "yes" || t == "on") {
    *out = true;
  } else if (t == "0" || t == "false" || t == "no" || t == "off") {
    *out = false;
  } else {
    return false;
  }
  return true;
}

bool ParseSettingValue(const SettingSpec& spec, const std::string& text, SettingValue* value,
                       std::string* why) {
  auto fail = [&](const std::string& expected) {
    if (why != nullptr) *why = "must be " + expected + ", got '" + text + "'";
    return false;
  };
  double number = 0;
  switch (spec.type) {
    case SettingType::kBool: {
      bool b = false;
      if (!ParseBoolText(text, &b)) return fail("a boolean (0/1, true/false)");
      *value = b;
      return true;
    }
    case SettingType::kInt: {
      int i = 0;
      if (!ParseIntText(text, &i)) return fail("an integer");
      number = i;
      *value = i;
      break;
    }
    case SettingType::kDouble:
      if (!ParseDoubleText(text, &number)) return fail("a finite number");
      *value = number;
      break;
    case SettingType::kString:
      *value = text;
      return true;
    case SettingType::kList: {
      std::vector<std::string> items;
      std::stringstream in(text);
      std::string item;
      while (std::getline(in, item, ',')) {
        if (!Trimmed(item).empty()) items.push_back(Trimmed(item));
      }
      *value = items;
      return true;
    }
  }
  if (number < spec.min || number > spec.max) return fail("in " + FormatSettingRange(spec));
  return true;
}

std::string FormatSettingValue(const SettingValue& value) {
  struct Visitor {
    std::string operator()(bool b) const { return b ? "true" : "false"; }
    std::string operator()(int i) const { return std::to_string(i); }
    std::string operator()(double d) const { return FormatNumber(d); }
    std::string operator()(const std::string& s) const { return s; }
    std::string operator()(const std::vector<std::string>& v) const {
      std::string out;
      for (const std::string& s : v) out += (out.empty() ? "" : ",") + s;
      return out;
    }
  };
  return std::visit(Visitor(), value);
}

std::string FormatSettingRange(const SettingSpec& spec) {
  if (spec.type != SettingType::kInt && spec.type != SettingType::kDouble) return "";
  if (std::isinf(spec.min) && std::isinf(spec.max)) return "";
  return "[" + FormatNumber(spec.min) + ", " + FormatNumber(spec.max) + "]";
}

size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const bool same = std::tolower(static_cast<unsigned char>(a[i - 1])) ==
                        std::tolower(static_cast<unsigned char>(b[j - 1]));
      const size_t next = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (same ? 0 : 1)});
      diagonal = row[j];
      row[j] = next;
    }
  }
  return row[b.size()];
}

std::string ClosestSettingKey(const std::string& key, const std::vector<SettingSpec>& known) {
  std::string best;
  size_t best_distance = std::numeric_limits<size_t>::max();
  for (const SettingSpec& spec : known) {
    const size_t d = EditDistance(key, spec.key);
    if (d < best_distance) {
      best = spec.key;
      best_distance = d;
    }
  }
  return best;
}

}  // namespace detslam
