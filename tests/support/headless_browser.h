// A real browser for tests: Debian's headless Chromium driven over the DevTools protocol on a
// pipe (--remote-debugging-pipe: JSON messages ended by a NUL byte on file descriptors 3 and 4),
// so a test can open a page, wait for what the page shows, run the page's own buttons and take a
// screenshot, as a person would.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace detslam::testing {

// $DETSLAM_CHROMIUM, else chromium-headless-shell or chromium on the PATH; "" if none.
std::string FindChromium();

class HeadlessBrowser {
 public:
  // Starts the browser and opens `url` in a page of width x height CSS pixels. Throws
  // std::runtime_error when it cannot be started or does not answer.
  HeadlessBrowser(const std::string& chromium, const std::string& url, int width = 1400,
                  int height = 720);
  ~HeadlessBrowser();
  HeadlessBrowser(const HeadlessBrowser&) = delete;
  HeadlessBrowser& operator=(const HeadlessBrowser&) = delete;

  // The value of a JavaScript expression in the page (promises awaited). Throws
  // std::runtime_error on a script exception or a timeout.
  nlohmann::json Evaluate(const std::string& expression);
  // Evaluates `condition` every 50 ms until it is true; false after `timeout`.
  bool WaitFor(const std::string& condition, std::chrono::milliseconds timeout);
  // A PNG screenshot of the page.
  std::vector<uint8_t> Screenshot();

 private:
  nlohmann::json Call(const std::string& method, const nlohmann::json& params,
                      bool in_page = true);
  void Send(const nlohmann::json& message);
  nlohmann::json Receive(std::chrono::milliseconds timeout);

  pid_t pid_ = -1;
  int to_browser_ = -1, from_browser_ = -1;
  std::string buffer_;  // bytes read, not yet a whole message
  int next_id_ = 1;
  std::string session_;  // the page's DevTools session
  std::string profile_dir_;
};

// Bytes of a base64 text.
std::vector<uint8_t> DecodeBase64(const std::string& text);

}  // namespace detslam::testing
