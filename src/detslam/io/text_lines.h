// Line-oriented text files as the TUM tools read them: '#' comments and blank lines skipped,
// fields split on spaces, tabs and commas. Errors name the file and the 1-based line.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace detslam {

// Calls `fn(line_number, fields)` for every data line. Throws InputError if the file cannot be
// opened (naming it).
void ForEachDataLine(const std::string& path,
                     const std::function<void(int, const std::vector<std::string>&)>& fn);

// Splits on spaces, tabs and commas, dropping empty fields.
std::vector<std::string> SplitFields(const std::string& line);

// Parses a finite double or throws InputError(path, line) naming the text.
double ParseDoubleField(const std::string& path, int line, const std::string& text);

}  // namespace detslam
