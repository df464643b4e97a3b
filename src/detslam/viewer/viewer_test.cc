// The viewer's parts without a browser: the encodings, the server's answers (malformed requests
// get 4xx; the update stream carries the newest state), and the live content's pause and step.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <condition_variable>
#include <mutex>
#include <cstring>
#include <future>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <thread>

#include "detslam/core/check.h"
#include "detslam/viewer/live_viewer.h"
#include "detslam/viewer/viewer_encode.h"
#include "detslam/viewer/viewer_server.h"

namespace detslam {
namespace {

using nlohmann::json;

ViewerFrame SampleFrame() {
  ViewerFrame f;
  f.seq = 7;
  f.index = 3;
  f.state = "ok";
  f.tracked = true;
  f.world_from_cam = Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.5, -1.25, 2));
  f.bgr = cv::Mat(48, 64, CV_8UC3, cv::Scalar(100, 100, 100));
  cv::Mat mask(48, 64, CV_8UC1, cv::Scalar(0));
  mask(cv::Rect(0, 0, 32, 48)).setTo(255);
  f.masks.push_back(mask);
  f.boxes.push_back(cv::Rect(0, 0, 32, 48));
  f.has_keypoints = true;
  f.keypoints[static_cast<int>(KeypointFate::kMatched)] = {10.5f, 20.f, 11.f, 21.25f};
  f.keypoints[static_cast<int>(KeypointFate::kMask)] = {5.f, 6.f};
  return f;
}

TEST(ViewerEncode, FrameJsonHoldsStatePoseAndKeypointsByFate) {
  const json j = json::parse(FrameJson(SampleFrame()));
  EXPECT_EQ(j["index"], 3);
  EXPECT_EQ(j["seq"], 7);
  EXPECT_EQ(j["state"], "ok");
  EXPECT_EQ(j["width"], 64);
  ASSERT_EQ(j["pose"].size(), 12u);
  EXPECT_DOUBLE_EQ(j["pose"][0].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(j["pose"][3].get<double>(), 0.5);
  EXPECT_DOUBLE_EQ(j["pose"][7].get<double>(), -1.25);
  EXPECT_DOUBLE_EQ(j["pose"][11].get<double>(), 2.0);
  EXPECT_EQ(j["keypoints"]["matched"], json::parse("[10.5, 20, 11, 21.25]"));
  EXPECT_EQ(j["keypoints"]["mask"], json::parse("[5, 6]"));
  EXPECT_TRUE(j["keypoints"]["depth"].empty());
  EXPECT_EQ(j["boxes"][0], json::parse("[0, 0, 32, 48]"));
  ViewerFrame none;
  EXPECT_TRUE(json::parse(FrameJson(none))["keypoints"].is_null());
  EXPECT_TRUE(json::parse(FrameJson(none))["pose"].is_null());
}

TEST(ViewerEncode, NumbersKeepFourDecimalsWithoutTrailingZeros) {
  ViewerMap m;
  m.trajectory = {Eigen::Vector3d(1.23456, -0.00001, 10), Eigen::Vector3d(-2.5, 0.1, 1e-4)};
  const std::string text = MapJson(m);
  EXPECT_NE(text.find("\"trajectory\":[1.2346,0,10,-2.5,0.1,0.0001]"), std::string::npos) << text;
  const json j = json::parse(text);
  EXPECT_EQ(j["points"], 0);
  EXPECT_TRUE(j["ground_truth"].empty());
}

TEST(ViewerEncode, MapPointsAreFloat32Triples) {
  ViewerMap m;
  m.points = {1.f, 2.f, 3.f, -4.5f, 0.f, 6.f};
  const std::string bytes = MapPointsBinary(m);
  ASSERT_EQ(bytes.size(), 24u);
  float back[6];
  std::memcpy(back, bytes.data(), 24);
  EXPECT_EQ(back[3], -4.5f);
  EXPECT_EQ(json::parse(MapJson(m))["points"], 2);
}

TEST(ViewerEncode, JpegShowsTheMaskTintedAndLeavesTheRunsPixelsAlone) {
  const ViewerFrame f = SampleFrame();
  const std::string jpeg = FrameJpeg(f);
  ASSERT_FALSE(jpeg.empty());
  const cv::Mat img = cv::imdecode(std::vector<uint8_t>(jpeg.begin(), jpeg.end()), cv::IMREAD_COLOR);
  ASSERT_EQ(img.size(), cv::Size(64, 48));
  const cv::Vec3b masked = img.at<cv::Vec3b>(24, 16), plain = img.at<cv::Vec3b>(24, 48);
  EXPECT_GT(masked[0], plain[0] + 40);  // blue up (cyan tint)
  EXPECT_NEAR(plain[0], 100, 4);
  EXPECT_EQ(f.bgr.at<cv::Vec3b>(24, 16), cv::Vec3b(100, 100, 100));  // drawn on a copy
  EXPECT_TRUE(FrameJpeg(ViewerFrame()).empty());
}

// A content whose state the test sets.
class FakeContent : public ViewerContent {
 public:
  std::string Title() const override { return "fake \"run\""; }
  uint64_t WaitForUpdate(uint64_t seen, std::chrono::milliseconds timeout) override {
    ++waits;
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait_for(lock, timeout, [&] { return update_ > seen; });
    return update_;
  }
  ViewerCounters Counters() const override {
    std::lock_guard<std::mutex> lock(mutex_);
    ViewerCounters c;
    c.mode = "live";
    c.frame = frame_ ? frame_->index : -1;
    return c;
  }
  std::shared_ptr<const ViewerFrame> Frame(int64_t index) override {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!frame_ || (index >= 0 && index != frame_->index)) return nullptr;
    return frame_;
  }
  std::shared_ptr<const ViewerMap> Map() override { return nullptr; }
  bool Control(const std::string& action, std::string* error) override {
    std::lock_guard<std::mutex> lock(mutex_);
    actions_.push_back(action);
    *error = "refused";
    return action != "resume";
  }
  void ClientsChanged(int delta) override { clients += delta; }
  void SetFrame(int64_t index) {
    std::lock_guard<std::mutex> lock(mutex_);
    auto f = std::make_shared<ViewerFrame>(SampleFrame());
    f->index = index;
    f->seq = ++update_;
    frame_ = f;
    changed_.notify_all();
  }
  std::vector<std::string> actions() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return actions_;
  }
  std::atomic<int> clients{0};
  std::atomic<int> waits{0};  // WaitForUpdate calls (a stream calls it after its first state)

 private:
  mutable std::mutex mutex_;  // the server calls from its threads
  std::vector<std::string> actions_;
  std::condition_variable changed_;
  uint64_t update_ = 0;
  std::shared_ptr<const ViewerFrame> frame_;
};

// Sends raw bytes to 127.0.0.1:port and returns everything the server answers until it closes
// the connection (or `read_for` passes).
std::string Exchange(int port, const std::string& request,
                     std::chrono::milliseconds read_for = std::chrono::milliseconds(3000)) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0) {
    ::close(fd);
    return "";
  }
  ::send(fd, request.data(), request.size(), MSG_NOSIGNAL);
  timeval tv{0, 100 * 1000};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
  std::string out;
  const auto end = std::chrono::steady_clock::now() + read_for;
  char buf[4096];
  while (std::chrono::steady_clock::now() < end) {
    const ssize_t n = ::recv(fd, buf, sizeof(buf), 0);
    if (n == 0) break;
    if (n > 0) out.append(buf, static_cast<size_t>(n));
  }
  ::close(fd);
  return out;
}

int Status(const std::string& response) {
  if (response.rfind("HTTP/1.1 ", 0) != 0) return -1;
  return std::stoi(response.substr(9, 3));
}

std::string Get(int port, const std::string& target) {
  return Exchange(port, "GET " + target + " HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n");
}

std::string Post(int port, const std::string& target, const std::string& body) {
  return Exchange(port, "POST " + target + " HTTP/1.1\r\nHost: x\r\nConnection: close\r\n" +
                            "Content-Length: " + std::to_string(body.size()) + "\r\n\r\n" + body);
}

TEST(ViewerServer, ServesThePageAndTheApi) {
  FakeContent content;
  content.SetFrame(4);
  ViewerServer server(&content, ViewerServerOptions());
  ASSERT_GT(server.port(), 0);
  EXPECT_EQ(server.url(), "http://127.0.0.1:" + std::to_string(server.port()) + "/");
  const std::string page = Get(server.port(), "/");
  EXPECT_EQ(Status(page), 200);
  EXPECT_NE(page.find("<canvas id=\"map3d\""), std::string::npos);
  EXPECT_EQ(Status(Get(server.port(), "/viewer.js")), 200);
  EXPECT_EQ(Status(Get(server.port(), "/viewer.css")), 200);
  const std::string info = Get(server.port(), "/api/info");
  EXPECT_EQ(json::parse(info.substr(info.find("\r\n\r\n") + 4))["title"], "fake \"run\"");
  const std::string frame = Get(server.port(), "/api/frame?index=4");
  ASSERT_EQ(Status(frame), 200);
  EXPECT_EQ(json::parse(frame.substr(frame.find("\r\n\r\n") + 4))["index"], 4);
  const std::string jpeg = Get(server.port(), "/api/frame.jpg?index=4");
  EXPECT_EQ(Status(jpeg), 200);
  EXPECT_NE(jpeg.find("Content-Type: image/jpeg"), std::string::npos);
  EXPECT_EQ(Status(Get(server.port(), "/api/map")), 200);
  EXPECT_EQ(Status(Post(server.port(), "/api/control", "step\n")), 200);
  EXPECT_EQ(Status(Post(server.port(), "/api/control", "resume")), 409);  // refused by the content
  EXPECT_EQ(content.actions(), (std::vector<std::string>{"step", "resume"}));
}

TEST(ViewerServer, MalformedRequestsGet4xxAndTheServerGoesOn) {
  FakeContent content;
  content.SetFrame(4);
  ViewerServer server(&content, ViewerServerOptions());
  const int port = server.port();
  EXPECT_EQ(Status(Get(port, "/nothing/here")), 404);
  EXPECT_EQ(Status(Get(port, "/api/frame?index=abc")), 400);
  EXPECT_EQ(Status(Get(port, "/api/frame?index=-3")), 400);
  EXPECT_EQ(Status(Get(port, "/api/frame?index=99999999999999999999")), 400);
  EXPECT_EQ(Status(Get(port, "/api/frame?index=5")), 404);  // not kept
  EXPECT_EQ(Status(Get(port, "/api/frame.jpg?index=")), 400);
  EXPECT_EQ(Status(Post(port, "/api/control", "dance")), 400);
  EXPECT_EQ(Status(Post(port, "/api/control", std::string(10000, 'x'))), 413);
  EXPECT_EQ(Status(Exchange(port, "GARBAGE\r\n\r\n")), 400);
  EXPECT_EQ(Status(Exchange(port, "GET /%zz%%/ HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n")), 404);
  const int bad_length = Status(Exchange(
      port, "POST /api/control HTTP/1.1\r\nContent-Length: abc\r\nConnection: close\r\n\r\nstep"));
  EXPECT_TRUE(bad_length >= 400 && bad_length < 500) << bad_length;
  Exchange(port, std::string(1 << 16, 'A'), std::chrono::milliseconds(500));  // no request line
  EXPECT_TRUE(content.actions().empty());
  EXPECT_EQ(Status(Get(port, "/api/frame?index=4")), 200);  // still serving
}

TEST(ViewerServer, TheUpdateStreamSendsTheNewestFrameAndCountsItsClients) {
  FakeContent content;
  content.SetFrame(1);
  ViewerServer server(&content, ViewerServerOptions());
  std::future<std::string> stream = std::async(std::launch::async, [&] {
    return Get(server.port(), "/api/events");  // read for 3 s
  });
  // The client counts once the server has taken the connection (on a loaded machine that can take
  // longer than a moment; the stream is read for 3 s).
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(2500);
  // ... and the stream has sent its first state once it waits for an update (under
  // ThreadSanitizer on a loaded machine the frames below once came before it: CI, 2026-12-06).
  while ((content.clients.load() == 0 || content.waits.load() == 0) &&
         std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_EQ(content.clients.load(), 1);
  EXPECT_GT(content.waits.load(), 0);
  for (int i = 2; i <= 50; ++i) content.SetFrame(i);  // faster than a page reads them
  const std::string text = stream.get();
  EXPECT_EQ(Status(text), 200);
  EXPECT_NE(text.find("text/event-stream"), std::string::npos);
  EXPECT_NE(text.find("\"index\":1,"), std::string::npos);   // the first state
  EXPECT_NE(text.find("\"index\":50,"), std::string::npos);  // and the newest
  size_t frames = 0;
  for (size_t p = text.find("event: frame"); p != std::string::npos; p = text.find("event: frame", p + 1)) ++frames;
  EXPECT_LT(frames, 50u);  // not every frame: the stream sends the newest, it does not queue
  server.Stop();
  EXPECT_EQ(content.clients.load(), 0);
}

TEST(ViewerServer, ABusyPortIsAClearError) {
  FakeContent content;
  ViewerServer first(&content, ViewerServerOptions());
  ViewerServerOptions same;
  same.port = first.port();
  try {
    ViewerServer second(&content, same);
    FAIL() << "bound a port in use";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(std::to_string(first.port())), std::string::npos) << e.what();
  }
  ViewerServerOptions bad;
  bad.port = 70000;
  EXPECT_THROW(ViewerServer(&content, bad), InputError);
}

TEST(ViewerServer, WithoutThreeJsThePageStillLoadsAndSaysWhy) {
  FakeContent content;
  ViewerServerOptions o;
  o.three_js = "/nonexistent/three.min.js";
  ViewerServer server(&content, o);
  EXPECT_FALSE(server.has_three_js());
  const std::string r = Get(server.port(), "/three.min.js");
  EXPECT_EQ(Status(r), 404);
  EXPECT_NE(r.find("libjs-three"), std::string::npos);
  EXPECT_EQ(Status(Get(server.port(), "/")), 200);
}

// The live content with a real (empty) SLAM system: pause, step and resume hold and release the
// runner's WaitBeforeFrame; a threaded run cannot be paused.
TEST(LiveViewer, StepRunsOneFrameAtATimeAndResumeRunsOn) {
  SlamOptions so;
  so.vocabulary = "none";
  SlamSystem slam(PinholeCamera(), so);
  std::atomic<bool> stop{false};
  LiveViewerOptions o;
  o.start_paused = true;
  o.stop = &stop;
  LiveViewer viewer(o);
  viewer.OnStart(10, /*pausable=*/true);
  EXPECT_TRUE(viewer.Counters().paused);
  std::atomic<int> passed{0};
  std::thread runner([&] {
    for (int i = 0; i < 5 && !stop; ++i) {
      viewer.WaitBeforeFrame(i, slam);
      ++passed;
    }
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_EQ(passed.load(), 0);
  std::string error;
  const uint64_t seq_before = viewer.Counters().seq;
  ASSERT_TRUE(viewer.Control("step", &error)) << error;
  EXPECT_GT(viewer.Counters().seq, seq_before);  // the page keeps the newest counters by this
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_EQ(passed.load(), 1);
  ASSERT_TRUE(viewer.Control("step", &error));
  ASSERT_TRUE(viewer.Control("step", &error));
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_EQ(passed.load(), 3);
  EXPECT_FALSE(viewer.Control("jump", &error));
  ASSERT_TRUE(viewer.Control("resume", &error));
  runner.join();
  EXPECT_EQ(passed.load(), 5);
  // A map snapshot asked for while paused is taken by the waiting runner.
  ASSERT_TRUE(viewer.Control("pause", &error));
  std::thread waiting([&] { viewer.WaitBeforeFrame(5, slam); });
  EXPECT_EQ(viewer.Map(), nullptr);
  for (int i = 0; i < 100 && viewer.map_snapshots() == 0; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_EQ(viewer.map_snapshots(), 1u);
  ASSERT_NE(viewer.Map(), nullptr);
  EXPECT_TRUE(viewer.Map()->points.empty());
  stop = true;  // a stop ends the pause
  waiting.join();

  LiveViewer threaded(LiveViewerOptions{});
  threaded.OnStart(10, /*pausable=*/false);
  EXPECT_FALSE(threaded.Control("pause", &error));
  EXPECT_NE(error.find("sequential"), std::string::npos);
}

}  // namespace
}  // namespace detslam
