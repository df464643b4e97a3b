#include "detslam/eval/svg_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <vector>

#include "detslam/core/atomic_file.h"
#include "detslam/eval/svg_draw.h"

namespace detslam {

using svg::Axes;
using svg::Escape;
using svg::Label;
using svg::Legend;
using svg::NiceStep;
using svg::Num;
using svg::Panel;
using svg::Polyline;
using svg::Range;

namespace {

constexpr double kWidth = 960;
constexpr const char* kGtColor = "#222222";
constexpr const char* kEstColor = "#1f77b4";
constexpr const char* kRotColor = "#d62728";

// Shades the untracked runs of the coverage over the time axis of `p` (times relative to t0).
void ShadeUntracked(std::ostringstream& os, const Panel& p, const CoverageResult& c, double t0) {
  for (size_t k = 0; k < c.tracked.size(); ++k) {
    if (c.tracked[k]) continue;
    size_t end = k;
    while (end + 1 < c.tracked.size() && !c.tracked[end + 1]) ++end;
    const double a = std::clamp(c.frame_stamps[k].Seconds() - t0, p.xr.lo, p.xr.hi);
    const double b = std::clamp(c.frame_stamps[end].Seconds() - t0, p.xr.lo, p.xr.hi);
    os << "<rect x='" << Num(p.X(a)) << "' y='" << Num(p.y) << "' width='"
       << Num(std::max(1.0, p.X(b) - p.X(a))) << "' height='" << Num(p.h)
       << "' fill='#ff9896' fill-opacity='0.35'/>\n";
    k = end;
  }
}

}  // namespace

std::string RenderEvalSvg(const EvalResult& r) {
  const std::vector<AtePair>& pairs = r.ate.pairs;
  // Top-view axes: the two of largest ground-truth spread, kept in x < y < z order.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero(), var = Eigen::Vector3d::Zero();
  for (const AtePair& p : pairs) mean += p.gt_position;
  if (!pairs.empty()) mean /= static_cast<double>(pairs.size());
  for (const AtePair& p : pairs) var += (p.gt_position - mean).cwiseAbs2();
  int drop = 0;
  var.minCoeff(&drop);
  const int ax = drop == 0 ? 1 : 0, ay = drop == 2 ? 1 : 2;
  const char* names[3] = {"x", "y", "z"};

  std::vector<double> xs, ys;
  for (const AtePair& p : pairs) {
    xs.push_back(p.gt_position[ax]);
    xs.push_back(p.est_aligned[ax]);
    ys.push_back(p.gt_position[ay]);
    ys.push_back(p.est_aligned[ay]);
  }
  Panel top{80, 70, 800, 440, Range::Of(xs, false), Range::Of(ys, false)};
  // Equal scale: widen the narrower range around its centre, then pad by 5%.
  const double ppm = std::min(top.w / (top.xr.hi - top.xr.lo), top.h / (top.yr.hi - top.yr.lo)) / 1.05;
  const double cx = 0.5 * (top.xr.lo + top.xr.hi), cy = 0.5 * (top.yr.lo + top.yr.hi);
  top.xr = {cx - top.w / ppm / 2, cx + top.w / ppm / 2};
  top.yr = {cy - top.h / ppm / 2, cy + top.h / ppm / 2};

  const double t0 = pairs.empty() ? 0.0 : pairs.front().est_stamp.Seconds();
  std::vector<double> ts, errs;
  for (const AtePair& p : pairs) {
    ts.push_back(p.est_stamp.Seconds() - t0);
    errs.push_back(p.error_m);
  }
  const Range time = Range::Of(ts, true);
  Panel ate{80, 580, 800, 200, time, Range::Of(errs, true)};
  ate.yr.hi *= 1.08;

  const bool per_s = r.rpe.per_second();
  const double div = per_s ? r.rpe.options.delta : 1.0;
  std::vector<double> rt, rr;
  for (const RpePair& p : r.rpe.pairs) {
    rt.push_back(p.trans_m / div);
    rr.push_back(p.rot_deg / div);
  }
  Panel rpe{80, 850, 800, 200, time, Range::Of(rt, true)};
  rpe.yr.hi *= 1.08;
  Range rot_range = Range::Of(rr, true);
  rot_range.hi *= 1.08;

  std::ostringstream os;
  os << "<?xml version='1.0' encoding='UTF-8'?>\n"
     << "<svg xmlns='http://www.w3.org/2000/svg' width='" << kWidth << "' height='1110' "
     << "viewBox='0 0 " << kWidth << " 1110' font-family='Helvetica, Arial, sans-serif' "
     << "font-size='11'>\n<rect width='100%' height='100%' fill='#fafafa'/>\n";
  char head[512];
  std::snprintf(head, sizeof(head),
                "ATE rmse %.4f m (%zu pairs, %s)   RPE %.4f %s / %.3f %s   tracked %.1f%%",
                r.ate.error_m.rmse, pairs.size(), r.options.with_scale ? "Sim(3)" : "SE(3)",
                r.rpe.trans_m.rmse / div, per_s ? "m/s" : "m", r.rpe.rot_deg.rmse / div,
                per_s ? "deg/s" : "deg", 100.0 * r.coverage.fraction);
  os << "<text x='80' y='24' font-size='16' font-weight='bold'>" << Escape(head) << "</text>\n";
  if (!r.est_path.empty()) {
    os << "<text x='80' y='42' fill='#555'>" << Escape(r.est_path) << "  vs  "
       << Escape(r.gt_path) << "</text>\n";
  }

  Axes(os, top, "(a) Top view: ground truth and aligned estimate",
       std::string(names[ax]) + " [m]", std::string(names[ay]) + " [m]");
  std::vector<std::pair<double, double>> gt_pts, est_pts;
  for (const AtePair& p : pairs) {
    gt_pts.emplace_back(top.X(p.gt_position[ax]), top.Y(p.gt_position[ay]));
    est_pts.emplace_back(top.X(p.est_aligned[ax]), top.Y(p.est_aligned[ay]));
  }
  Polyline(os, gt_pts, kGtColor, 1.5);
  Polyline(os, est_pts, kEstColor, 1.5);
  if (!gt_pts.empty()) {
    os << "<circle cx='" << Num(gt_pts.front().first) << "' cy='" << Num(gt_pts.front().second)
       << "' r='4' fill='#2ca02c'><title>start</title></circle>\n";
  }
  Legend(os, top.x + top.w - 200, top.y + 10,
         {{"ground truth", kGtColor}, {"estimate (aligned)", kEstColor}});

  Axes(os, ate, "(b) ATE over time (shaded: frames without estimate)", "time [s]",
       "translation error [m]");
  ShadeUntracked(os, ate, r.coverage, t0);
  std::vector<std::pair<double, double>> ate_pts;
  for (size_t k = 0; k < ts.size(); ++k) ate_pts.emplace_back(ate.X(ts[k]), ate.Y(errs[k]));
  Polyline(os, ate_pts, kEstColor, 1.2);
  Legend(os, ate.x + ate.w - 200, ate.y + 10, {{"ATE [m]", kEstColor}});

  char rpe_title[160];
  std::snprintf(rpe_title, sizeof(rpe_title), "(c) RPE over time (delta %g %s)",
                r.rpe.options.delta, RpeDeltaUnitName(r.rpe.options.unit));
  Axes(os, rpe, rpe_title, "window start time [s]",
       per_s ? "translation [m/s]" : "translation [m]");
  // Right axis for rotation.
  const double rs = NiceStep(rot_range.hi - rot_range.lo, 5);
  for (double v = 0; v <= rot_range.hi + 1e-9 * rs; v += rs) {
    os << "<text x='" << Num(rpe.x + rpe.w + 6) << "' y='" << Num(rpe.Y2(v, rot_range) + 4)
       << "' fill='" << kRotColor << "'>" << Label(v) << "</text>\n";
  }
  os << "<text transform='translate(" << Num(rpe.x + rpe.w + 52) << "," << Num(rpe.y + rpe.h / 2)
     << ") rotate(90)' text-anchor='middle' fill='" << kRotColor << "'>"
     << (per_s ? "rotation [deg/s]" : "rotation [deg]") << "</text>\n";
  std::vector<std::pair<double, double>> rt_pts, rr_pts;
  for (size_t k = 0; k < r.rpe.pairs.size(); ++k) {
    const double t = std::clamp(r.rpe.pairs[k].est_from.Seconds() - t0, time.lo, time.hi);
    rt_pts.emplace_back(rpe.X(t), rpe.Y(rt[k]));
    rr_pts.emplace_back(rpe.X(t), rpe.Y2(rr[k], rot_range));
  }
  Polyline(os, rt_pts, kEstColor, 1.2);
  Polyline(os, rr_pts, kRotColor, 1.0);
  Legend(os, rpe.x + rpe.w - 200, rpe.y + 10,
         {{per_s ? "translation [m/s]" : "translation [m]", kEstColor},
          {per_s ? "rotation [deg/s]" : "rotation [deg]", kRotColor}});
  if (r.rpe.pairs.empty()) {
    os << "<text x='" << Num(rpe.x + rpe.w / 2) << "' y='" << Num(rpe.y + rpe.h / 2)
       << "' text-anchor='middle' fill='#888'>no RPE pairs</text>\n";
  }
  os << "</svg>\n";
  return os.str();
}

void WriteEvalSvg(const std::string& path, const EvalResult& result) {
  const std::string svg = RenderEvalSvg(result);
  WriteFileAtomically(path, [&](std::ostream& out) { out << svg; });
}

}  // namespace detslam
