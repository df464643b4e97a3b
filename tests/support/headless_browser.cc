#include "support/headless_browser.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <thread>

namespace detslam::testing {
namespace {

constexpr auto kCallTimeout = std::chrono::seconds(30);

bool Executable(const std::string& path) { return ::access(path.c_str(), X_OK) == 0; }

}  // namespace

std::string FindChromium() {
  const char* env = std::getenv("DETSLAM_CHROMIUM");
  if (env != nullptr && *env != '\0') return Executable(env) ? env : "";
  const char* path = std::getenv("PATH");
  const std::string dirs = path ? path : "/usr/bin:/bin";
  for (const char* name : {"chromium-headless-shell", "chromium"}) {
    size_t start = 0;
    while (start <= dirs.size()) {
      const size_t end = dirs.find(':', start);
      const std::string dir = dirs.substr(start, end == std::string::npos ? std::string::npos : end - start);
      const std::string candidate = (dir.empty() ? "." : dir) + "/" + name;
      if (Executable(candidate)) return candidate;
      if (end == std::string::npos) break;
      start = end + 1;
    }
  }
  return "";
}

HeadlessBrowser::HeadlessBrowser(const std::string& chromium, const std::string& url, int width,
                                 int height) {
  profile_dir_ = (std::filesystem::temp_directory_path() /
                  ("detslam_chromium_" + std::to_string(::getpid()) + "_" +
                   std::to_string(reinterpret_cast<uintptr_t>(this))))
                     .string();
  std::filesystem::create_directories(profile_dir_);
  int in[2], out[2];  // in: test -> browser (its fd 3); out: browser -> test (its fd 4)
  if (::pipe(in) != 0 || ::pipe(out) != 0) throw std::runtime_error("pipe() failed");
  pid_ = ::fork();
  if (pid_ < 0) throw std::runtime_error("fork() failed");
  if (pid_ == 0) {
    ::dup2(in[0], 3);
    ::dup2(out[1], 4);
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, STDOUT_FILENO);
    ::dup2(null, STDERR_FILENO);
    for (int fd = 5; fd < 1024; ++fd) ::close(fd);
    const std::string profile = "--user-data-dir=" + profile_dir_;
    const std::string size = "--window-size=" + std::to_string(width) + "," + std::to_string(height);
    ::execl(chromium.c_str(), chromium.c_str(), "--headless", "--no-sandbox",
            "--enable-unsafe-swiftshader", "--use-angle=swiftshader", "--remote-debugging-pipe",
            "--no-first-run", "--disable-gpu-sandbox", "--disable-dev-shm-usage",
            profile.c_str(), size.c_str(), "about:blank", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  ::close(in[0]);
  ::close(out[1]);
  to_browser_ = in[1];
  from_browser_ = out[0];
  ::signal(SIGPIPE, SIG_IGN);  // a browser that died fails the write, not the test binary
  const nlohmann::json target = Call("Target.createTarget",
                                     {{"url", url}, {"width", width}, {"height", height}},
                                     /*in_page=*/false);
  const nlohmann::json attached = Call(
      "Target.attachToTarget", {{"targetId", target.at("targetId")}, {"flatten", true}}, false);
  session_ = attached.at("sessionId").get<std::string>();
  Call("Emulation.setDeviceMetricsOverride",
       {{"width", width}, {"height", height}, {"deviceScaleFactor", 1}, {"mobile", false}});
}

HeadlessBrowser::~HeadlessBrowser() {
  if (to_browser_ >= 0) ::close(to_browser_);
  if (from_browser_ >= 0) ::close(from_browser_);
  if (pid_ > 0) {
    ::kill(pid_, SIGKILL);
    int status = 0;
    ::waitpid(pid_, &status, 0);
  }
  std::error_code ec;
  std::filesystem::remove_all(profile_dir_, ec);
}

void HeadlessBrowser::Send(const nlohmann::json& message) {
  std::string bytes = message.dump();
  bytes.push_back('\0');
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(to_browser_, bytes.data() + done, bytes.size() - done);
    if (n <= 0) throw std::runtime_error("the browser has gone (write failed)");
    done += static_cast<size_t>(n);
  }
}

nlohmann::json HeadlessBrowser::Receive(std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (true) {
    const size_t nul = buffer_.find('\0');
    if (nul != std::string::npos) {
      const std::string message = buffer_.substr(0, nul);
      buffer_.erase(0, nul + 1);
      return nlohmann::json::parse(message);
    }
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        end - std::chrono::steady_clock::now());
    if (left.count() <= 0) throw std::runtime_error("the browser did not answer in time");
    pollfd p{from_browser_, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(left.count())) <= 0) continue;
    char chunk[65536];
    const ssize_t n = ::read(from_browser_, chunk, sizeof(chunk));
    if (n <= 0) throw std::runtime_error("the browser has gone (its pipe closed)");
    buffer_.append(chunk, static_cast<size_t>(n));
  }
}

nlohmann::json HeadlessBrowser::Call(const std::string& method, const nlohmann::json& params,
                                     bool in_page) {
  const int id = next_id_++;
  nlohmann::json message = {{"id", id}, {"method", method}, {"params", params}};
  if (in_page) message["sessionId"] = session_;
  Send(message);
  const auto end = std::chrono::steady_clock::now() + kCallTimeout;
  while (true) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        end - std::chrono::steady_clock::now());
    const nlohmann::json reply = Receive(std::max(left, std::chrono::milliseconds(1)));
    if (!reply.contains("id") || reply.at("id") != id) continue;  // an event, or another reply
    if (reply.contains("error")) throw std::runtime_error(method + ": " + reply.at("error").dump());
    return reply.value("result", nlohmann::json::object());
  }
}

nlohmann::json HeadlessBrowser::Evaluate(const std::string& expression) {
  const nlohmann::json r = Call("Runtime.evaluate", {{"expression", expression},
                                                     {"returnByValue", true},
                                                     {"awaitPromise", true}});
  if (r.contains("exceptionDetails"))
    throw std::runtime_error("script error in `" + expression + "`: " + r.at("exceptionDetails").dump());
  return r.at("result").value("value", nlohmann::json());
}

bool HeadlessBrowser::WaitFor(const std::string& condition, std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < end) {
    const nlohmann::json v = Evaluate("Boolean(" + condition + ")");
    if (v.is_boolean() && v.get<bool>()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
}

std::vector<uint8_t> HeadlessBrowser::Screenshot() {
  const nlohmann::json r = Call("Page.captureScreenshot", {{"format", "png"}});
  return DecodeBase64(r.at("data").get<std::string>());
}

std::vector<uint8_t> DecodeBase64(const std::string& text) {
  std::vector<uint8_t> out;
  uint32_t acc = 0;
  int bits = 0;
  for (char c : text) {
    int v;
    if (c >= 'A' && c <= 'Z') v = c - 'A';
    else if (c >= 'a' && c <= 'z') v = c - 'a' + 26;
    else if (c >= '0' && c <= '9') v = c - '0' + 52;
    else if (c == '+') v = 62;
    else if (c == '/') v = 63;
    else continue;  // padding, line breaks
    acc = (acc << 6) | static_cast<uint32_t>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<uint8_t>((acc >> bits) & 0xff));
    }
  }
  return out;
}

}  // namespace detslam::testing
