// The viewer's local web server (cpp-httplib): the page and its scripts (built into the binary;
// three.js from Debian's libjs-three), the update stream and the data the page asks for. Bound to
// 127.0.0.1 only. Requests it cannot answer get a 4xx status, never a crash.
//
//   GET  /                      the page (also /viewer.js, /viewer.css, /three.min.js)
//   GET  /api/events            Server-Sent Events: "counters", "frame" and "map" (newest only:
//                               a slow page skips updates, the run never waits for it)
//   GET  /api/counters          the counters (JSON)
//   GET  /api/frame[?index=N]   a frame's state and keypoints (JSON; default the newest)
//   GET  /api/frame.jpg?index=N its image with the dynamic masks drawn (JPEG)
//   GET  /api/map               keyframes, trajectory, aligned ground truth (JSON)
//   GET  /api/map_points        the map points (float32 x, y, z, little-endian)
//   POST /api/control           body "pause", "resume" or "step" (sequential runs)
#pragma once

#include <atomic>
#include <memory>
#include <string>
#include <thread>

#include "detslam/viewer/viewer_content.h"

namespace httplib {
class Server;
}

namespace detslam {

struct ViewerServerOptions {
  int port = 0;                          // 0: a free port
  std::string host = "127.0.0.1";        // local only
  std::string three_js;                  // three.min.js to serve ("": DefaultThreeJsPath())
  int max_streams = 4;                   // update streams at once (more get 503)
  bool Check(std::string* error) const;
};

// $DETSLAM_THREE_JS, else Debian's /usr/share/javascript/three/three.min.js.
std::string DefaultThreeJsPath();

class ViewerServer {
 public:
  // Serves `content` (which must outlive the server). Throws InputError when the port cannot be
  // bound. Without three.js the page still shows the frame and counters and says what is missing.
  ViewerServer(ViewerContent* content, const ViewerServerOptions& options);
  ~ViewerServer();  // Stop()
  ViewerServer(const ViewerServer&) = delete;
  ViewerServer& operator=(const ViewerServer&) = delete;

  int port() const { return port_; }
  std::string url() const;
  bool has_three_js() const { return !three_js_.empty(); }
  // Ends the update streams and the server; idempotent.
  void Stop();

 private:
  void AddRoutes();

  ViewerContent* content_;
  ViewerServerOptions options_;
  std::string three_js_;  // the script's bytes ("" when not found)
  std::unique_ptr<httplib::Server> server_;
  std::thread thread_;
  int port_ = 0;
  std::atomic<bool> stopping_{false};
  std::atomic<int> streams_{0};
};

}  // namespace detslam
