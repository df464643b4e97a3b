// Loud invariant checks (broken invariants are bugs: abort with a message), and the exception type
// for bad input at the boundary (files, settings, command lines).
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace detslam {

// Bad input or configuration: the message names the file (and line where there is one).
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
  InputError(const std::string& file, int line, const std::string& message)
      : std::runtime_error(Format(file, line, message)) {}

 private:
  static std::string Format(const std::string& file, int line, const std::string& message) {
    std::ostringstream os;
    os << file;
    if (line > 0) os << ":" << line;
    os << ": " << message;
    return os.str();
  }
};

[[noreturn]] void CheckFailed(const char* file, int line, const char* condition,
                              const std::string& message);

}  // namespace detslam

#define DETSLAM_CHECK(condition)                                                  \
  do {                                                                            \
    if (!(condition)) ::detslam::CheckFailed(__FILE__, __LINE__, #condition, ""); \
  } while (0)

#define DETSLAM_CHECK_MSG(condition, message)                                          \
  do {                                                                                 \
    if (!(condition)) {                                                                \
      std::ostringstream detslam_check_os_;                                            \
      detslam_check_os_ << message;                                                    \
      ::detslam::CheckFailed(__FILE__, __LINE__, #condition, detslam_check_os_.str()); \
    }                                                                                  \
  } while (0)
