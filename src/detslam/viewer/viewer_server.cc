#include "detslam/viewer/viewer_server.h"

#include <httplib.h>
#include <sys/socket.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <thread>

#include "detslam/core/check.h"
#include "detslam/viewer/viewer_assets.h"
#include "detslam/viewer/viewer_encode.h"

namespace detslam {
namespace {

constexpr auto kStreamWait = std::chrono::milliseconds(500);  // keep-alive period of a stream

void Reply(httplib::Response& res, int status, const std::string& message) {
  res.status = status;
  std::string escaped;
  for (char c : message) {
    if (c == '"' || c == '\\') escaped.push_back('\\');
    if (static_cast<unsigned char>(c) >= 0x20) escaped.push_back(c);
  }
  res.set_content("{\"error\":\"" + escaped + "\"}", "application/json");
}

// "index" query parameter: absent -> -1; digits only (at most 12), else false.
bool ParseIndex(const httplib::Request& req, int64_t* index) {
  *index = -1;
  if (!req.has_param("index")) return true;
  const std::string v = req.get_param_value("index");
  if (v.empty() || v.size() > 12) return false;
  for (char c : v) {
    if (c < '0' || c > '9') return false;
  }
  *index = std::stoll(v);
  return true;
}

std::string Trim(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  const size_t e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

struct StreamState {
  uint64_t seen = 0, frame_seq = 0, map_seq = 0;
  bool first = true;
};

}  // namespace

bool ViewerServerOptions::Check(std::string* error) const {
  if (port < 0 || port > 65535) {
    *error = "viewer port must be in [0, 65535] (0: a free one), got " + std::to_string(port);
    return false;
  }
  if (max_streams < 1) {
    *error = "max_streams must be >= 1";
    return false;
  }
  return true;
}

std::string DefaultThreeJsPath() {
  const char* env = std::getenv("DETSLAM_THREE_JS");
  if (env != nullptr && *env != '\0') return env;
  return "/usr/share/javascript/three/three.min.js";
}

ViewerServer::ViewerServer(ViewerContent* content, const ViewerServerOptions& options)
    : content_(content), options_(options), server_(std::make_unique<httplib::Server>()) {
  std::string error;
  if (!options_.Check(&error)) throw InputError(error);
  const std::string three = options_.three_js.empty() ? DefaultThreeJsPath() : options_.three_js;
  std::ifstream in(three, std::ios::binary);
  if (in) {
    std::ostringstream ss;
    ss << in.rdbuf();
    three_js_ = ss.str();
  } else {
    spdlog::warn("viewer: {} not found (Debian: apt-get install libjs-three): no 3-D view", three);
  }
  server_->new_task_queue = [] { return new httplib::ThreadPool(12); };
  server_->set_keep_alive_timeout(2);
  server_->set_payload_max_length(4096);
  // SO_REUSEADDR only: httplib's default also sets SO_REUSEPORT, which would let a second viewer
  // listen on a port that is in use instead of failing.
  server_->set_socket_options([](int sock) {
    const int yes = 1;
    ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
  });
  server_->set_exception_handler(
      [](const httplib::Request&, httplib::Response& res, std::exception_ptr ep) {
        std::string what = "internal error";
        try {
          if (ep) std::rethrow_exception(ep);
        } catch (const std::exception& e) {
          what = e.what();
        } catch (...) {
        }
        Reply(res, 500, what);
      });
  AddRoutes();
  port_ = options_.port == 0 ? server_->bind_to_any_port(options_.host)
                             : (server_->bind_to_port(options_.host, options_.port) ? options_.port
                                                                                    : -1);
  if (port_ <= 0) {
    throw InputError("viewer: cannot listen on " + options_.host + ":" +
                     std::to_string(options_.port) + " (port in use?)");
  }
  thread_ = std::thread([this] { server_->listen_after_bind(); });
  // httplib's stop() does nothing before the listening thread has entered its accept loop, which
  // would then accept for ever and the destructor's join hang: return once it listens.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (!server_->is_running() && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  if (!server_->is_running()) {  // its listen ended at once (the thread has finished)
    stopping_ = true;
    thread_.join();
    throw InputError("viewer: the server on " + options_.host + ":" + std::to_string(port_) +
                     " did not start");
  }
}

ViewerServer::~ViewerServer() { Stop(); }

std::string ViewerServer::url() const {
  return "http://" + options_.host + ":" + std::to_string(port_) + "/";
}

void ViewerServer::Stop() {
  if (stopping_.exchange(true)) return;
  server_->stop();
  if (thread_.joinable()) thread_.join();
}

void ViewerServer::AddRoutes() {
  httplib::Server& s = *server_;
  for (const ViewerAsset& asset : ViewerAssets()) {
    const std::string path = asset.name == "index.html" ? "/" : "/" + asset.name;
    s.Get(path, [asset](const httplib::Request&, httplib::Response& res) {
      res.set_header("Cache-Control", "no-cache");
      res.set_content(asset.bytes, asset.mime);
    });
  }
  s.Get("/three.min.js", [this](const httplib::Request&, httplib::Response& res) {
    if (three_js_.empty()) return Reply(res, 404, "three.js not installed (apt-get install libjs-three)");
    res.set_content(three_js_, "text/javascript");
  });
  s.Get("/api/counters", [this](const httplib::Request&, httplib::Response& res) {
    res.set_content(CountersJson(content_->Counters()), "application/json");
  });
  s.Get("/api/info", [this](const httplib::Request&, httplib::Response& res) {
    const std::string title = content_->Title();
    std::string escaped;
    for (char c : title) {
      if (c == '"' || c == '\\') escaped.push_back('\\');
      if (static_cast<unsigned char>(c) >= 0x20) escaped.push_back(c);
    }
    res.set_content("{\"title\":\"" + escaped + "\",\"three_js\":" +
                        (three_js_.empty() ? "false" : "true") + "}",
                    "application/json");
  });
  s.Get("/api/frame", [this](const httplib::Request& req, httplib::Response& res) {
    int64_t index = -1;
    if (!ParseIndex(req, &index)) return Reply(res, 400, "index must be a frame number");
    const auto frame = content_->Frame(index);
    if (!frame) return Reply(res, 404, "no such frame (not yet, or no longer kept)");
    res.set_content(FrameJson(*frame), "application/json");
  });
  s.Get("/api/frame.jpg", [this](const httplib::Request& req, httplib::Response& res) {
    int64_t index = -1;
    if (!ParseIndex(req, &index)) return Reply(res, 400, "index must be a frame number");
    const auto frame = content_->Frame(index);
    if (!frame) return Reply(res, 404, "no such frame (not yet, or no longer kept)");
    const std::string jpeg = FrameJpeg(*frame);
    if (jpeg.empty()) return Reply(res, 404, "the frame has no image");
    res.set_header("Cache-Control", "no-cache");
    res.set_content(jpeg, "image/jpeg");
  });
  s.Get("/api/map", [this](const httplib::Request&, httplib::Response& res) {
    const auto map = content_->Map();
    res.set_content(map ? MapJson(*map) : MapJson(ViewerMap()), "application/json");
  });
  s.Get("/api/map_points", [this](const httplib::Request&, httplib::Response& res) {
    const auto map = content_->Map();
    res.set_content(map ? MapPointsBinary(*map) : std::string(), "application/octet-stream");
  });
  s.Post("/api/control", [this](const httplib::Request& req, httplib::Response& res) {
    const std::string action = Trim(req.body);
    if (action != "pause" && action != "resume" && action != "step")
      return Reply(res, 400, "the body must be pause, resume or step");
    std::string error;
    if (!content_->Control(action, &error)) return Reply(res, 409, error);
    res.set_content(CountersJson(content_->Counters()), "application/json");
  });
  s.Get("/api/events", [this](const httplib::Request&, httplib::Response& res) {
    if (streams_.fetch_add(1) >= options_.max_streams) {
      --streams_;
      return Reply(res, 503, "too many viewer pages open");
    }
    content_->ClientsChanged(+1);
    auto state = std::make_shared<StreamState>();
    res.set_header("Cache-Control", "no-cache");
    res.set_chunked_content_provider(
        "text/event-stream",
        [this, state](size_t, httplib::DataSink& sink) {
          if (stopping_) return false;
          const uint64_t update =
              state->first ? 1 : content_->WaitForUpdate(state->seen, kStreamWait);
          if (stopping_) return false;
          std::string msg;
          if (!state->first && update == state->seen) {
            msg = ": keep-alive\n\n";  // also finds a page that has gone (the write fails)
          } else {
            state->first = false;
            state->seen = update;
            msg = "event: counters\ndata: " + CountersJson(content_->Counters()) + "\n\n";
            const auto frame = content_->Frame(-1);
            if (frame && frame->seq != state->frame_seq) {
              state->frame_seq = frame->seq;
              msg += "event: frame\ndata: " + FrameJson(*frame) + "\n\n";
            }
            const auto map = content_->Map();
            if (map && map->seq != state->map_seq) {
              state->map_seq = map->seq;
              msg += "event: map\ndata: {\"seq\":" + std::to_string(map->seq) + "}\n\n";
            }
          }
          return sink.write(msg.data(), msg.size());
        },
        [this](bool) {
          --streams_;
          content_->ClientsChanged(-1);
        });
  });
}

}  // namespace detslam
