// Generic machinery for declared settings keys: a key's spec (name, type, default, range, help),
// parsing a value's text with type and range checks, formatting values, and the closest known key
// to a misspelt one. The keys themselves are declared once, in pipeline/settings_keys.cc.
#pragma once

#include <limits>
#include <string>
#include <variant>
#include <vector>

namespace detslam {

enum class SettingType { kBool, kInt, kDouble, kString, kList };

// A typed value; kList is a comma-separated list of names in the settings text.
using SettingValue = std::variant<bool, int, double, std::string, std::vector<std::string>>;

struct SettingSpec {
  std::string key;  // e.g. "Dynamic.Alpha"
  SettingType type = SettingType::kString;
  SettingValue default_value;                             // the options struct's in-class default
  double min = -std::numeric_limits<double>::infinity();  // inclusive range (kInt, kDouble)
  double max = std::numeric_limits<double>::infinity();
  std::string help;  // one line
};

// "bool", "int", "double", "string", "list".
const char* ToString(SettingType type);

// Text -> value with the spec's type and range. On failure returns false and sets `why` to e.g.
// "must be an integer, got 'x'" or "must be in [1, inf], got 0".
bool ParseSettingValue(const SettingSpec& spec, const std::string& text, SettingValue* value,
                       std::string* why);

// Value -> settings text (lists comma-separated); ParseSettingValue reads it back.
std::string FormatSettingValue(const SettingValue& value);

// "[min, max]" for numeric keys with a bound, else "".
std::string FormatSettingRange(const SettingSpec& spec);

// Levenshtein distance (case-insensitive).
size_t EditDistance(const std::string& a, const std::string& b);

// The known key closest to `key` by edit distance (ties: the first); "" if `known` is empty.
std::string ClosestSettingKey(const std::string& key, const std::vector<SettingSpec>& known);

// Text parsing shared with the settings reader. Doubles must be finite; integers accept a real
// with an integral value ("640.0"); booleans accept true/false, yes/no, on/off (any case), 1/0.
bool ParseDoubleText(const std::string& text, double* out);
bool ParseIntText(const std::string& text, int* out);
bool ParseBoolText(const std::string& text, bool* out);

}  // namespace detslam
