#include "detslam/eval/run_report.h"

#include <algorithm>
#include <cstdio>
#include <sstream>
#include <vector>

#include "detslam/core/atomic_file.h"
#include "detslam/core/stats.h"
#include "detslam/eval/svg_draw.h"
#include "detslam/eval/svg_plot.h"

namespace detslam {
namespace {

constexpr const char* kBlue = "#1f77b4";
constexpr const char* kOrange = "#ff7f0e";
constexpr const char* kGreen = "#2ca02c";
constexpr const char* kRed = "#d62728";
constexpr const char* kPurple = "#9467bd";
constexpr const char* kGrey = "#7f7f7f";

using Series = std::vector<std::pair<double, double>>;

// One line of `value(frame)` over the frame index in panel `p`, against range `r`.
template <typename Fn>
Series Line(const RunLog& run, const svg::Panel& p, const svg::Range& r, Fn value) {
  Series s;
  for (const RunFrameLog& f : run.per_frame) {
    s.emplace_back(p.X(static_cast<double>(f.index)), p.Y2(value(f), r));
  }
  return s;
}

// Shades runs of frames without a pose.
void ShadeLost(std::ostringstream& os, const RunLog& run, const svg::Panel& p) {
  const auto& fr = run.per_frame;
  for (size_t k = 0; k < fr.size(); ++k) {
    if (fr[k].tracked) continue;
    size_t end = k;
    while (end + 1 < fr.size() && !fr[end + 1].tracked) ++end;
    const double a = p.X(static_cast<double>(fr[k].index) - 0.5);
    const double b = p.X(static_cast<double>(fr[end].index) + 0.5);
    os << "<rect x='" << svg::Num(a) << "' y='" << svg::Num(p.y) << "' width='"
       << svg::Num(std::max(1.0, b - a)) << "' height='" << svg::Num(p.h)
       << "' fill='#ff9896' fill-opacity='0.35'/>\n";
    k = end;
  }
}

// Right-hand axis labels for range `r`.
void RightAxis(std::ostringstream& os, const svg::Panel& p, const svg::Range& r,
               const std::string& label, const char* color) {
  const double step = svg::NiceStep(r.hi - r.lo, 4);
  for (double v = 0; v <= r.hi + 1e-9 * step; v += step) {
    os << "<text x='" << svg::Num(p.x + p.w + 6) << "' y='" << svg::Num(p.Y2(v, r) + 4)
       << "' fill='" << color << "'>" << svg::Label(v) << "</text>\n";
  }
  os << "<text transform='translate(" << svg::Num(p.x + p.w + 44) << "," << svg::Num(p.y + p.h / 2)
     << ") rotate(90)' text-anchor='middle' fill='" << color << "'>" << svg::Escape(label)
     << "</text>\n";
}

svg::Range MaxRange(const RunLog& run, double (*value)(const RunFrameLog&)) {
  std::vector<double> v;
  for (const RunFrameLog& f : run.per_frame) v.push_back(value(f));
  svg::Range r = svg::Range::Of(v, true);
  r.hi *= 1.08;
  return r;
}

std::string Fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, v);
  return buf;
}

// Longest run of frames without a pose.
size_t LongestLost(const RunLog& run) {
  size_t longest = 0, cur = 0;
  for (const RunFrameLog& f : run.per_frame) {
    cur = f.tracked ? 0 : cur + 1;
    longest = std::max(longest, cur);
  }
  return longest;
}

// The map of the atlas each frame was tracked in: a strip of colours along the top of panel `p`,
// and the merges as dashed full-height lines.
void DrawMaps(std::ostringstream& os, const RunLog& run, const svg::Panel& p) {
  static const char* kMapColors[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728",
                                     "#9467bd", "#8c564b", "#e377c2", "#17becf"};
  for (const RunFrameLog& f : run.per_frame) {
    if (f.map < 0) continue;
    const double a = p.X(static_cast<double>(f.index) - 0.5);
    const double b = p.X(static_cast<double>(f.index) + 0.5);
    os << "<rect x='" << svg::Num(a) << "' y='" << svg::Num(p.y + 1) << "' width='"
       << svg::Num(std::max(0.5, b - a)) << "' height='6' fill='" << kMapColors[f.map % 8]
       << "'><title>frame " << f.index << ": map " << f.map << "</title></rect>\n";
  }
  for (int64_t frame : run.maps.merge_frames) {
    const double x = p.X(static_cast<double>(frame));
    os << "<line x1='" << svg::Num(x) << "' y1='" << svg::Num(p.y) << "' x2='" << svg::Num(x)
       << "' y2='" << svg::Num(p.y + p.h) << "' stroke='" << kOrange
       << "' stroke-width='2' stroke-dasharray='5,3'><title>maps merged at frame " << frame
       << "</title></line>\n";
  }
}

// "A-B (n frames)" for every stretch of frames without a pose.
std::string LostStretches(const RunLog& run) {
  std::string out;
  const auto& fr = run.per_frame;
  int shown = 0;
  for (size_t k = 0; k < fr.size(); ++k) {
    if (fr[k].tracked) continue;
    size_t end = k;
    while (end + 1 < fr.size() && !fr[end + 1].tracked) ++end;
    if (++shown <= 12) {
      out += (out.empty() ? "" : ", ") + std::to_string(fr[k].index) + "-" +
             std::to_string(fr[end].index) + " (" + std::to_string(end - k + 1) + ")";
    }
    k = end;
  }
  if (shown > 12) out += ", ... (" + std::to_string(shown) + " stretches)";
  return out.empty() ? "none" : out;
}

std::string TableRow(const std::string& key, const std::string& value) {
  return "<tr><th>" + svg::Escape(key) + "</th><td>" + svg::Escape(value) + "</td></tr>\n";
}

}  // namespace

std::string RenderRunSvg(const RunLog& run) {
  constexpr double kW = 960, kH = 860;
  std::vector<double> idx;
  for (const RunFrameLog& f : run.per_frame) idx.push_back(static_cast<double>(f.index));
  svg::Range frames = svg::Range::Of(idx, true);
  const svg::Range track_r = MaxRange(run, [](const RunFrameLog& f) {
    return static_cast<double>(std::max(f.keypoints, f.inliers));
  });
  const svg::Range dyn_r = MaxRange(run, [](const RunFrameLog& f) {
    return static_cast<double>(std::max(f.rejected_keypoints, f.geometric_rejected));
  });
  const svg::Range inst_r =
      MaxRange(run, [](const RunFrameLog& f) { return static_cast<double>(f.dynamic_instances); });
  const svg::Range time_r = MaxRange(run, [](const RunFrameLog& f) {
    return std::max({f.segmentation_ms, f.extraction_ms, f.tracking_ms, f.mapping_ms});
  });
  const svg::Panel track{80, 60, 800, 200, frames, track_r};
  const svg::Panel dyn{80, 340, 800, 200, frames, dyn_r};
  const svg::Panel time{80, 620, 800, 180, frames, time_r};

  std::ostringstream os;
  os << "<svg xmlns='http://www.w3.org/2000/svg' width='" << kW << "' height='" << kH
     << "' viewBox='0 0 " << kW << " " << kH << "' font-family='Helvetica, Arial, sans-serif' "
     << "font-size='11'>\n<rect width='100%' height='100%' fill='#fafafa'/>\n";

  svg::Axes(os, track, "(a) Tracking: keypoints and landmark inliers (shaded: no pose)", "frame",
            "count");
  ShadeLost(os, run, track);
  for (const RunFrameLog& f : run.per_frame) {  // keyframes: ticks on the bottom edge
    if (!f.keyframe) continue;
    const double x = track.X(static_cast<double>(f.index));
    os << "<line x1='" << svg::Num(x) << "' y1='" << svg::Num(track.y + track.h) << "' x2='"
       << svg::Num(x) << "' y2='" << svg::Num(track.y + track.h - 8) << "' stroke='" << kGreen
       << "'/>\n";
  }
  DrawMaps(os, run, track);
  for (const RunFrameLog& f : run.per_frame) {  // loop closures: full-height lines
    if (!f.loop_closed) continue;
    const double x = track.X(static_cast<double>(f.index));
    os << "<line x1='" << svg::Num(x) << "' y1='" << svg::Num(track.y) << "' x2='" << svg::Num(x)
       << "' y2='" << svg::Num(track.y + track.h) << "' stroke='" << kPurple
       << "' stroke-width='2'><title>loop closed at frame " << f.index << "</title></line>\n";
  }
  svg::Polyline(os,
                Line(run, track, track_r,
                     [](const RunFrameLog& f) { return static_cast<double>(f.keypoints); }),
                kGrey, 1.0);
  svg::Polyline(os,
                Line(run, track, track_r,
                     [](const RunFrameLog& f) { return static_cast<double>(f.inliers); }),
                kBlue, 1.2);
  svg::Legend(os, track.x + track.w - 200, track.y + 10,
              {{"keypoints", kGrey},
               {"landmark inliers", kBlue},
               {"keyframe (tick)", kGreen},
               {"loop closed", kPurple},
               {"maps merged (dashed); strip: map", kOrange}});

  svg::Axes(os, dyn, "(b) Dynamic objects: rejected keypoints per frame", "frame", "keypoints");
  RightAxis(os, dyn, inst_r, "dynamic objects", kGrey);
  svg::Polyline(os,
                Line(run, dyn, inst_r,
                     [](const RunFrameLog& f) { return static_cast<double>(f.dynamic_instances); }),
                kGrey, 1.0);
  svg::Polyline(
      os,
      Line(run, dyn, dyn_r,
           [](const RunFrameLog& f) { return static_cast<double>(f.rejected_keypoints); }),
      kRed, 1.2);
  svg::Polyline(
      os,
      Line(run, dyn, dyn_r,
           [](const RunFrameLog& f) { return static_cast<double>(f.geometric_rejected); }),
      kOrange, 1.2);
  svg::Legend(
      os, dyn.x + dyn.w - 200, dyn.y + 10,
      {{"dynamic filter", kRed}, {"geometric check", kOrange}, {"dynamic objects (right)", kGrey}});

  svg::Axes(os, time, "(c) Time per frame and stage", "frame", "ms");
  svg::Polyline(os, Line(run, time, time_r, [](const RunFrameLog& f) { return f.segmentation_ms; }),
                kPurple, 1.0);
  svg::Polyline(os, Line(run, time, time_r, [](const RunFrameLog& f) { return f.extraction_ms; }),
                kBlue, 1.0);
  svg::Polyline(os, Line(run, time, time_r, [](const RunFrameLog& f) { return f.tracking_ms; }),
                kGreen, 1.0);
  svg::Polyline(os, Line(run, time, time_r, [](const RunFrameLog& f) { return f.mapping_ms; }),
                kOrange, 1.0);
  svg::Legend(os, time.x + time.w - 200, time.y + 10,
              {{"segmentation", kPurple},
               {"extraction + filter", kBlue},
               {"tracking", kGreen},
               {"local mapping (keyframes)", kOrange}});
  if (run.per_frame.empty()) {
    os << "<text x='480' y='160' text-anchor='middle' fill='#888'>no frames in the run "
          "log</text>\n";
  }
  os << "</svg>\n";
  return os.str();
}

std::string RenderHtmlReport(const RunLog& run, const EvalResult* eval) {
  std::vector<double> seg, ext, trk;
  for (const RunFrameLog& f : run.per_frame) {
    if (f.segmentation_ms > 0) seg.push_back(f.segmentation_ms);
    ext.push_back(f.extraction_ms);
    trk.push_back(f.tracking_ms);
  }
  std::ostringstream os;
  os << "<!DOCTYPE html>\n<html lang='en'>\n<head>\n<meta charset='utf-8'>\n<title>detslam report: "
     << svg::Escape(run.dataset) << "</title>\n<style>\n"
     << "body{font-family:Helvetica,Arial,sans-serif;margin:24px;max-width:1000px;color:#222}\n"
     << "table{border-collapse:collapse;margin:8px 0 20px}th,td{border:1px solid #ccc;padding:3px "
        "8px;"
     << "text-align:left;vertical-align:top}th{background:#f0f0f0;font-weight:normal}\n"
     << "code{font-size:90%}.bad{color:#b00}\n</style>\n</head>\n<body>\n";
  os << "<h1>detslam run report</h1>\n<h2>Run</h2>\n<table>\n";
  os << TableRow("run log", run.path) << TableRow("dataset", run.dataset)
     << TableRow("settings", run.settings) << TableRow("mode", run.mode)
     << TableRow("segmenter", run.segmenter);
  const size_t lost = LongestLost(run);
  os << "<tr><th>frames tracked</th><td" << (run.frames_tracked < run.frames ? " class='bad'" : "")
     << ">" << run.frames_tracked << " / " << run.frames << " ("
     << Fixed(100.0 * run.TrackedFraction(), 1) << " %); longest run without pose: " << lost
     << " frames</td></tr>\n";
  if (run.maps.main >= 0) {
    os << TableRow("maps (atlas)",
                   "started " + std::to_string(run.maps.started) + ", merged " +
                       std::to_string(run.maps.merged) + ", left " +
                       std::to_string(run.maps.left) + "; trajectory.txt (map " +
                       std::to_string(run.maps.main) + "): " +
                       std::to_string(run.maps.frames_in_main) + " frames" +
                       (run.maps.left > 1 ? "; the other maps: trajectory_map<N>.txt" : ""))
       << TableRow("stretches without a pose (frames)", LostStretches(run));
  }
  os << TableRow("keyframes / map points",
                 std::to_string(run.keyframes) + " / " + std::to_string(run.map_points))
     << TableRow("relocalisations / loops closed",
                 std::to_string(run.relocalizations) + " / " + std::to_string(run.loops_closed))
     << TableRow("wall time",
                 Fixed(run.wall_s, 1) + " s (" + Fixed(run.FramesPerSecond(), 1) + " frames/s)");
  if (run.realtime.offered > 0) {
    const RunRealtimeLog& t = run.realtime;
    os << TableRow("camera rate",
                   std::to_string(t.offered) + " frames offered, " + std::to_string(t.dropped) +
                       " dropped (" + Fixed(100.0 * t.dropped / t.offered, 1) +
                       " %) because the pipeline was busy; " + Fixed(t.processed_fps, 1) +
                       " frames/s processed; latency from arrival to pose: median " +
                       Fixed(t.latency_median_ms, 1) + " ms, 99th percentile " +
                       Fixed(t.latency_p99_ms, 1) + " ms, max " + Fixed(t.latency_max_ms, 1) +
                       " ms" +
                       (t.keyframes_mapped_in_burst >= 0
                            ? "; " + std::to_string(t.keyframes_mapped_in_burst) +
                                  " keyframes mapped without fusion or bundle adjustment while "
                                  "more waited"
                            : std::string()));
    if (t.asynchronous) {
      os << TableRow("asynchronous segmentation",
                     std::to_string(t.frames_segmented) +
                         " frames segmented; masks carried to each frame were " +
                         Fixed(t.mask_age_median, 0) + " frames old (median; max " +
                         Fixed(t.mask_age_max, 0) + "); " + std::to_string(t.keyframes_deferred) +
                         " keyframes deferred for stale masks, " +
                         std::to_string(t.keyframes_stale_masks) +
                         " made with stale masks after waiting");
    }
  }
  const ErrorStats s = ComputeErrorStats(seg), e = ComputeErrorStats(ext),
                   t = ComputeErrorStats(trk);
  os << TableRow("median ms per frame",
                 (s.count ? "segmentation " + Fixed(s.median, 1) + ", " : std::string()) +
                     "extraction + filter " + Fixed(e.median, 1) + ", tracking " +
                     Fixed(t.median, 1))
     << "</table>\n";
  if (eval != nullptr) {
    const EvalResult& r = *eval;
    const bool per_s = r.rpe.per_second();
    const double div = per_s ? r.rpe.options.delta : 1.0;
    os << "<h2>Accuracy</h2>\n<p>Against <code>" << svg::Escape(r.gt_path)
       << "</code> with the TUM RGB-D "
       << "tools' conventions (association within " << svg::Label(r.options.max_difference_s)
       << " s, " << (r.options.with_scale ? "Sim(3)" : "SE(3)") << " alignment).</p>\n<table>\n"
       << "<tr><th></th><th>RMSE</th><th>mean</th><th>median</th><th>max</th></tr>\n"
       << "<tr><th>ATE (mm)</th><td>" << Fixed(1000 * r.ate.error_m.rmse, 1) << "</td><td>"
       << Fixed(1000 * r.ate.error_m.mean, 1) << "</td><td>"
       << Fixed(1000 * r.ate.error_m.median, 1) << "</td><td>" << Fixed(1000 * r.ate.error_m.max, 1)
       << "</td></tr>\n"
       << "<tr><th>RPE translation (" << (per_s ? "mm/s" : "mm") << ")</th><td>"
       << Fixed(1000 * r.rpe.trans_m.rmse / div, 1) << "</td><td>"
       << Fixed(1000 * r.rpe.trans_m.mean / div, 1) << "</td><td>"
       << Fixed(1000 * r.rpe.trans_m.median / div, 1) << "</td><td>"
       << Fixed(1000 * r.rpe.trans_m.max / div, 1) << "</td></tr>\n"
       << "<tr><th>RPE rotation (" << (per_s ? "deg/s" : "deg") << ")</th><td>"
       << Fixed(r.rpe.rot_deg.rmse / div, 3) << "</td><td>" << Fixed(r.rpe.rot_deg.mean / div, 3)
       << "</td><td>" << Fixed(r.rpe.rot_deg.median / div, 3) << "</td><td>"
       << Fixed(r.rpe.rot_deg.max / div, 3) << "</td></tr>\n</table>\n"
       << "<p>Frames with ground truth that have a pose: " << r.coverage.frames_tracked << " / "
       << r.coverage.frames_with_gt << " (" << Fixed(100.0 * r.coverage.fraction, 1)
       << " %).</p>\n";
    std::string figure = RenderEvalSvg(r);
    if (figure.rfind("<?xml", 0) == 0) figure = figure.substr(figure.find('\n') + 1);
    os << figure;
  } else {
    os << "<h2>Accuracy</h2>\n<p>No ground truth given (<code>detslam report --gt FILE</code>), "
          "so no accuracy section.</p>\n";
  }
  os << "<h2>Per frame</h2>\n"
     << RenderRunSvg(run) << "<p>Made by <code>detslam report</code>.</p>\n</body>\n</html>\n";
  return os.str();
}

void WriteHtmlReport(const std::string& path, const RunLog& run, const EvalResult* eval) {
  const std::string html = RenderHtmlReport(run, eval);
  WriteFileAtomically(path, [&](std::ostream& out) { out << html; });
}

}  // namespace detslam
