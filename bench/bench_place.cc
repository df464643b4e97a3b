// Place-recognition benchmark (issue "place recognition", first target): the time of one
// relocalisation query, Tracker::RelocalizeFrame (bag-of-words candidates, matching within
// direct-index nodes, PnP RANSAC, pose optimisation, projection search), against the map size.
//
// The map is built from synthetic frames rendered in memory (synth/, people off): sequences of
// several presets and seeds (a seed gives the room other textures and the camera path other
// phases), one keyframe every `stride` frames at its ground-truth pose, one landmark per keypoint
// with depth (back-projected with the ground-truth pose). A keyframe shares the landmarks of the
// previous keyframes of its sequence that SearchByProjection finds in it at the ground-truth pose,
// so that covisibility exists as in a SLAM map. The map grows sequence by sequence and is measured
// when it holds each of the requested sizes. Queries are frames between keyframes of the
// sequences already in the smallest map, the same queries at every size.
// Usage: bench_place --json FILE [--sizes 250,500,1000,2000,5000] [--stride 8]
//   [--keyframes-per-sequence 50] [--queries-per-sequence 30] [--repeats 5]
//   [--presets static,loop,walking_halfsphere,walking_rpy] [--no-covisibility] [--seed 42]
// Progress goes to stderr; the JSON holds settings, per-size summaries and per-query results.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numeric>
#include <opencv2/core/utility.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "detslam/features/orb_extractor.h"
#include "detslam/map/frame.h"
#include "detslam/map/map.h"
#include "detslam/map/place_candidates.h"
#include "detslam/map/projection_search.h"
#include "detslam/pipeline/slam_system.h"
#include "detslam/place/default_vocabulary.h"
#include "detslam/synth/sequence.h"
#include "detslam/tracking/tracker.h"

namespace detslam {
namespace {

using Clock = std::chrono::steady_clock;

double MsSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

struct BenchOptions {
  std::string json;                                       // output file (required)
  std::vector<int> sizes = {250, 500, 1000, 2000, 5000};  // map sizes measured (keyframes)
  int stride = 8;                                         // frames between keyframes of a sequence
  int keyframes_per_sequence = 50;                        // keyframes taken from each sequence
  int queries_per_sequence = 30;  // queries from each sequence of the smallest map
  // Timed runs per query; the fastest is its time (the run least disturbed by other processes on
  // a shared host), the median of the runs is recorded too.
  int repeats = 5;
  std::vector<std::string> presets = {"static", "loop", "walking_halfsphere", "walking_rpy"};
  bool covisibility = true;     // share landmarks with earlier keyframes by projection
  int covisible_keyframes = 2;  // previous keyframes of the sequence projected into a new one
  uint64_t seed = 42;           // relocalisation RANSAC seed (TrackerOptions::seed)
};

std::vector<std::string> Split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

BenchOptions ParseArgs(int argc, char** argv) {
  BenchOptions o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw std::runtime_error("missing value after " + a);
      return argv[++i];
    };
    if (a == "--json") {
      o.json = value();
    } else if (a == "--sizes") {
      o.sizes.clear();
      for (const auto& s : Split(value())) o.sizes.push_back(std::stoi(s));
    } else if (a == "--stride") {
      o.stride = std::stoi(value());
    } else if (a == "--keyframes-per-sequence") {
      o.keyframes_per_sequence = std::stoi(value());
    } else if (a == "--queries-per-sequence") {
      o.queries_per_sequence = std::stoi(value());
    } else if (a == "--repeats") {
      o.repeats = std::stoi(value());
    } else if (a == "--presets") {
      o.presets = Split(value());
    } else if (a == "--no-covisibility") {
      o.covisibility = false;
    } else if (a == "--seed") {
      o.seed = std::stoull(value());
    } else {
      throw std::runtime_error("unknown argument " + a + " (see the comment at the top of " +
                               "bench/bench_place.cc)");
    }
  }
  if (o.json.empty()) throw std::runtime_error("--json FILE is required");
  if (o.sizes.empty() || o.stride < 2 || o.keyframes_per_sequence < 1 || o.repeats < 1 ||
      o.queries_per_sequence < 1 || o.presets.empty()) {
    throw std::runtime_error("bad options");
  }
  std::sort(o.sizes.begin(), o.sizes.end());
  if (o.sizes.front() < o.keyframes_per_sequence)
    throw std::runtime_error("the smallest size must hold at least one whole sequence");
  return o;
}

// Sequence i of the map: presets cycle fastest, then the seed (the room's textures) changes.
struct SequenceSpec {
  std::string preset;
  uint64_t seed = 1;
  int start = 0;  // first frame (loop sequences of different seeds start elsewhere on the lap)
};

SequenceSpec SpecOf(const BenchOptions& o, int i) {
  SequenceSpec s;
  s.preset = o.presets[static_cast<size_t>(i) % o.presets.size()];
  s.seed = 1 + static_cast<uint64_t>(i) / o.presets.size();
  s.start = static_cast<int>((s.seed - 1) * 240 % 960);
  return s;
}

struct QueryFrame {
  int sequence = 0;
  int frame = 0;  // frame number in its sequence
  Frame frame_data;
  Rigid3d world_from_cam;  // ground truth
};

class PlaceBench {
 public:
  explicit PlaceBench(BenchOptions options)
      : o_(std::move(options)),
        extractor_(OrbOptions{}),
        vocabulary_(LoadSharedVocabulary("")),
        camera_(SynthCamera()),
        map_(MakeScaleInfo(extractor_)) {}

  nlohmann::json Run();

 private:
  std::shared_ptr<FrameFeatures> Extract(const SynthFrame& f);
  void AddKeyFrame(int sequence, const SynthFrame& f);
  nlohmann::json Measure();

  BenchOptions o_;
  OrbExtractor extractor_;
  std::shared_ptr<const Vocabulary> vocabulary_;
  PinholeCamera camera_;
  Map map_;
  std::vector<QueryFrame> queries_;
  std::vector<KeyFrameId> sequence_keyframes_;             // keyframes of the sequence being added
  std::vector<int> keyframe_sequence_;                     // per keyframe id: its sequence
  double render_ms_ = 0, extract_ms_ = 0, insert_ms_ = 0;  // build time by step
  int64_t shared_observations_ = 0;
};

std::shared_ptr<FrameFeatures> PlaceBench::Extract(const SynthFrame& f) {
  const auto t0 = Clock::now();
  const cv::Mat gray = f.Gray(), depth_m = f.DepthMetres(camera_.depth_map_factor);
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  extractor_.Extract(gray, cv::Mat(), &keypoints, &descriptors);
  std::vector<float> depth = SampleKeypointDepth(keypoints, depth_m);
  auto features = BuildFrameFeatures(camera_, std::move(keypoints), descriptors, std::move(depth));
  ComputeFrameBow(*vocabulary_, features.get());
  extract_ms_ += MsSince(t0);
  return features;
}

void PlaceBench::AddKeyFrame(int sequence, const SynthFrame& f) {
  std::shared_ptr<FrameFeatures> features = Extract(f);
  const auto t0 = Clock::now();
  KeyFrame kf;
  kf.frame_index = f.index;
  kf.stamp = f.stamp;
  kf.cam_from_world = f.world_from_cam.Inverse();
  kf.features = features;
  const KeyFrameId id = map_.AddKeyFrame(std::move(kf));
  keyframe_sequence_.push_back(sequence);
  const FrameFeatures& ff = *features;
  std::vector<LandmarkId> touched;
  if (o_.covisibility) {
    // Landmarks of the previous keyframes of this sequence, found in this one by projection at the
    // ground-truth pose (with a depth check), become shared observations.
    std::set<LandmarkId> seen;
    std::vector<ProjectionCandidate> cands;
    const size_t n = sequence_keyframes_.size();
    const size_t from = n > static_cast<size_t>(o_.covisible_keyframes)
                            ? n - static_cast<size_t>(o_.covisible_keyframes)
                            : 0;
    for (size_t k = n; k-- > from;) {
      for (LandmarkId lm : map_.keyframe(sequence_keyframes_[k]).landmarks) {
        if (lm != kNoLandmark && seen.insert(lm).second)
          cands.push_back(CandidateFromLandmark(map_.landmark(lm)));
      }
    }
    const std::vector<bool> taken(ff.size(), false);
    const Rigid3d cam_from_world = f.world_from_cam.Inverse();
    const std::vector<int> m = SearchByProjection(camera_, map_.scale(), ff, cam_from_world, cands,
                                                  taken, ProjectionSearchOptions{});
    for (size_t c = 0; c < cands.size(); ++c) {
      if (m[c] < 0) continue;
      const size_t idx = static_cast<size_t>(m[c]);
      const double z = (cam_from_world * cands[c].position).z();
      if (map_.keyframe(id).landmarks[idx] != kNoLandmark || ff.depth[idx] <= 0 ||
          std::abs(ff.depth[idx] - z) > 0.05 * z) {
        continue;
      }
      map_.AddObservation(cands[c].landmark, id, idx);
      touched.push_back(cands[c].landmark);
      ++shared_observations_;
    }
  }
  for (size_t i = 0; i < ff.size(); ++i) {
    if (ff.depth[i] <= 0 || map_.keyframe(id).landmarks[i] != kNoLandmark) continue;
    const Eigen::Vector3d p = f.world_from_cam * camera_.Unproject(ff.undist[i], ff.depth[i]);
    const LandmarkId lm = map_.AddLandmark(p, id);
    map_.AddObservation(lm, id, i);
    touched.push_back(lm);
  }
  for (LandmarkId lm : touched) {
    map_.UpdateLandmarkGeometry(lm);
    map_.UpdateLandmarkDescriptor(lm);
  }
  map_.UpdateConnections(id);
  sequence_keyframes_.push_back(id);
  insert_ms_ += MsSince(t0);
}

double Percentile(std::vector<double> v, double p) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const double pos = p * static_cast<double>(v.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(pos));
  const size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

double Median(std::vector<double> v) { return Percentile(std::move(v), 0.5); }
double Min(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }

nlohmann::json PlaceBench::Measure() {
  cv::setNumThreads(1);  // single-threaded figure, as the tracking thread runs it
  TrackerOptions tracker_options;
  tracker_options.seed = o_.seed;
  std::vector<double> total_ms, total_median_ms, cand_ms, n_cands, errors_cm;
  std::vector<double> index_entries, sharing_keyframes, query_words;
  int successes = 0, same_room = 0;
  nlohmann::json per_query = nlohmann::json::array();
  for (const QueryFrame& q : queries_) {
    std::vector<double> t_total, t_cand;
    size_t num_candidates = 0;
    KeyFrameId result = kNoKeyFrame;
    Frame frame;
    for (int r = 0; r < o_.repeats; ++r) {
      const auto t0 = Clock::now();
      const std::vector<PlaceCandidate> c =
          RelocalizationCandidates(map_, q.frame_data.features->bow);
      t_cand.push_back(MsSince(t0));
      num_candidates = c.size();
      // A fresh tracker per run: every query starts from the same RANSAC seed.
      Tracker tracker(camera_, tracker_options);
      frame = q.frame_data;
      const auto t1 = Clock::now();
      result = tracker.RelocalizeFrame(map_, &frame);
      t_total.push_back(MsSince(t1));
    }
    // Size of the inverted-index work (untimed): entries on the query's words' lists, and the
    // keyframes sharing at least one word with the query.
    size_t entries = 0;
    std::set<KeyFrameId> sharing;
    for (const auto& word_weight : q.frame_data.features->bow) {
      const std::vector<KeyFrameId> ids = map_.place_index().KeyFramesWithWord(word_weight.first);
      entries += ids.size();
      sharing.insert(ids.begin(), ids.end());
    }
    index_entries.push_back(static_cast<double>(entries));
    query_words.push_back(static_cast<double>(q.frame_data.features->bow.size()));
    sharing_keyframes.push_back(static_cast<double>(sharing.size()));
    nlohmann::json j = {{"sequence", q.sequence},
                        {"frame", q.frame},
                        {"total_ms", Min(t_total)},
                        {"total_ms_median_of_runs", Median(t_total)},
                        {"candidates_ms", Min(t_cand)},
                        {"candidates", num_candidates},
                        {"success", result != kNoKeyFrame},
                        {"index_entries", entries},
                        {"keyframes_sharing_a_word", sharing.size()}};
    total_ms.push_back(Min(t_total));
    total_median_ms.push_back(Median(t_total));
    cand_ms.push_back(Min(t_cand));
    n_cands.push_back(static_cast<double>(num_candidates));
    if (result != kNoKeyFrame) {
      ++successes;
      const Eigen::Vector3d c_est = frame.cam_from_world->Inverse().translation();
      const double err_cm = (c_est - q.world_from_cam.translation()).norm() * 100.0;
      const double rot_deg =
          (q.world_from_cam.Inverse() * frame.cam_from_world->Inverse()).RotationAngle() * 180.0 /
          3.14159265358979323846;
      errors_cm.push_back(err_cm);
      const int kf_seq = keyframe_sequence_[static_cast<size_t>(result)];
      same_room += SpecOf(o_, kf_seq).seed == SpecOf(o_, q.sequence).seed ? 1 : 0;
      j["keyframe"] = result;
      j["keyframe_sequence"] = kf_seq;
      j["position_error_cm"] = err_cm;
      j["rotation_error_deg"] = rot_deg;
    }
    per_query.push_back(j);
  }
  cv::setNumThreads(-1);
  const double n = static_cast<double>(queries_.size());
  return {{"keyframes", map_.NumKeyFrames()},
          {"landmarks", map_.NumLandmarks()},
          {"queries", queries_.size()},
          {"total_ms",
           {{"median", Median(total_ms)},
            {"p90", Percentile(total_ms, 0.9)},
            {"max", *std::max_element(total_ms.begin(), total_ms.end())},
            {"mean", std::accumulate(total_ms.begin(), total_ms.end(), 0.0) / n}}},
          {"total_ms_median_of_runs",
           {{"median", Median(total_median_ms)}, {"p90", Percentile(total_median_ms, 0.9)}}},
          {"candidates_ms", {{"median", Median(cand_ms)}, {"p90", Percentile(cand_ms, 0.9)}}},
          {"candidates", {{"median", Median(n_cands)}, {"max", Percentile(n_cands, 1.0)}}},
          {"query_words", {{"median", Median(query_words)}}},
          {"index_entries", {{"median", Median(index_entries)}}},
          {"keyframes_sharing_a_word", {{"median", Median(sharing_keyframes)}}},
          {"success_rate", successes / n},
          {"successes", successes},
          {"same_room", same_room},
          {"position_error_cm",
           {{"median", Median(errors_cm)},
            {"p90", Percentile(errors_cm, 0.9)},
            {"max", Percentile(errors_cm, 1.0)}}},
          {"per_query", per_query}};
}

nlohmann::json PlaceBench::Run() {
  const int k = o_.keyframes_per_sequence;
  const int query_sequences = o_.sizes.front() / k;  // sequences wholly in the smallest map
  nlohmann::json sizes = nlohmann::json::array();
  const auto start = Clock::now();
  size_t next_size = 0;
  for (int s = 0; next_size < o_.sizes.size(); ++s) {
    const SequenceSpec spec = SpecOf(o_, s);
    SynthOptions so;
    so.preset = spec.preset;
    so.seed = spec.seed;
    so.people = false;
    so.frames = spec.start + k * o_.stride;
    const auto t0 = Clock::now();
    const SyntheticSequence seq(so);
    sequence_keyframes_.clear();
    if (s < query_sequences) {
      // Queries (rendered first, so that the smallest map is measured with all of them): frames
      // half-way between keyframes, spread over the sequence.
      for (int q = 0; q < o_.queries_per_sequence; ++q) {
        const int slot = q * k / o_.queries_per_sequence;
        const int frame = spec.start + slot * o_.stride + o_.stride / 2;
        const auto tr = Clock::now();
        const SynthFrame f = seq.Render(frame);
        render_ms_ += MsSince(tr);
        QueryFrame qf;
        qf.sequence = s;
        qf.frame = frame;
        qf.world_from_cam = f.world_from_cam;
        qf.frame_data.index = 1000000 * s + frame;
        qf.frame_data.stamp = f.stamp;
        qf.frame_data.features = Extract(f);
        queries_.push_back(std::move(qf));
      }
    }
    for (int j = 0; j < k && next_size < o_.sizes.size(); ++j) {
      const auto tr = Clock::now();
      const SynthFrame f = seq.Render(spec.start + j * o_.stride);
      render_ms_ += MsSince(tr);
      AddKeyFrame(s, f);
      if (static_cast<int>(map_.NumKeyFrames()) == o_.sizes[next_size]) {
        std::fprintf(stderr,
                     "[bench_place] map of %zu keyframes, %zu landmarks: measuring %zu "
                     "queries x %d runs\n",
                     map_.NumKeyFrames(), map_.NumLandmarks(), queries_.size(), o_.repeats);
        const auto tm = Clock::now();
        sizes.push_back(Measure());
        const nlohmann::json& r = sizes.back();
        std::fprintf(stderr,
                     "[bench_place]   median %.2f ms, p90 %.2f ms, success %.0f %% "
                     "(%.1f s)\n",
                     r["total_ms"]["median"].get<double>(), r["total_ms"]["p90"].get<double>(),
                     100 * r["success_rate"].get<double>(), MsSince(tm) / 1000);
        ++next_size;
      }
    }
    std::fprintf(stderr,
                 "[bench_place] sequence %d (%s, seed %llu, frames %d..): %zu keyframes, "
                 "%zu landmarks, %zu queries; %.1f s this sequence, %.0f s in all\n",
                 s, spec.preset.c_str(), static_cast<unsigned long long>(spec.seed), spec.start,
                 map_.NumKeyFrames(), map_.NumLandmarks(), queries_.size(), MsSince(t0) / 1000,
                 MsSince(start) / 1000);
  }
  nlohmann::json settings = {{"sizes", o_.sizes},
                             {"stride", o_.stride},
                             {"keyframes_per_sequence", k},
                             {"queries_per_sequence", o_.queries_per_sequence},
                             {"query_sequences", query_sequences},
                             {"repeats", o_.repeats},
                             {"presets", o_.presets},
                             {"covisibility", o_.covisibility},
                             {"covisible_keyframes", o_.covisible_keyframes},
                             {"seed", o_.seed},
                             {"vocabulary", DefaultVocabularyPath()},
                             {"orb_features", OrbOptions{}.num_features}};
  nlohmann::json sequences = nlohmann::json::array();
  for (int s = 0; s < static_cast<int>((o_.sizes.back() + k - 1) / k); ++s) {
    const SequenceSpec spec = SpecOf(o_, s);
    sequences.push_back({{"preset", spec.preset}, {"seed", spec.seed}, {"start", spec.start}});
  }
  return {{"settings", settings},
          {"sequences", sequences},
          {"build",
           {{"seconds", MsSince(start) / 1000},
            {"render_ms", render_ms_},
            {"extract_ms", extract_ms_},
            {"insert_ms", insert_ms_},
            {"shared_observations", shared_observations_}}},
          {"sizes", sizes}};
}

}  // namespace
}  // namespace detslam

int main(int argc, char** argv) {
  try {
    spdlog::set_level(spdlog::level::warn);
    const detslam::BenchOptions options = detslam::ParseArgs(argc, argv);
    detslam::PlaceBench bench(options);
    const nlohmann::json result = bench.Run();
    std::ofstream out(options.json);
    out << result.dump(1) << "\n";
    if (!out) throw std::runtime_error("cannot write " + options.json);
    std::fprintf(stderr, "[bench_place] wrote %s\n", options.json.c_str());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_place: %s\n", e.what());
    return 1;
  }
}
