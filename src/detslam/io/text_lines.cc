#include "detslam/io/text_lines.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "detslam/core/check.h"

namespace detslam {

std::vector<std::string> SplitFields(const std::string& line) {
  std::vector<std::string> fields;
  std::string cur;
  for (char c : line) {
    if (c == ' ' || c == '\t' || c == ',' || c == '\r') {
      if (!cur.empty()) fields.push_back(std::move(cur));
      cur.clear();
    } else {
      cur.push_back(c);
    }
  }
  if (!cur.empty()) fields.push_back(std::move(cur));
  return fields;
}

void ForEachDataLine(const std::string& path,
                     const std::function<void(int, const std::vector<std::string>&)>& fn) {
  if (std::filesystem::is_directory(path)) throw InputError(path, 0, "is a folder, expected a file");
  std::ifstream in(path);
  if (!in) throw InputError(path, 0, "cannot open file (missing or unreadable)");
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    fn(line_no, SplitFields(line));
  }
  if (in.bad()) throw InputError(path, line_no, "read error");
}

double ParseDoubleField(const std::string& path, int line, const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0') throw InputError(path, line, "malformed number '" + text + "'");
  if (!std::isfinite(v)) throw InputError(path, line, "non-finite number '" + text + "'");
  return v;
}

}  // namespace detslam
