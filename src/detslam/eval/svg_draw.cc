#include "detslam/eval/svg_draw.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace detslam::svg {

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.2f", v);
  return buf;
}

std::string Label(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%g", std::abs(v) < 1e-12 ? 0.0 : v);
  return buf;
}

std::string Escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '&')
      out += "&amp;";
    else if (c == '\'')
      out += "&#39;";
    else if (c == '"')
      out += "&quot;";
    else
      out += c;
  }
  return out;
}

double NiceStep(double span, int target) {
  const double raw = span / std::max(1, target);
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * p >= raw) return m * p;
  }
  return 10 * p;
}

void Range::Include(double v) {
  lo = std::min(lo, v);
  hi = std::max(hi, v);
}

Range Range::Of(const std::vector<double>& v, bool from_zero) {
  Range r;
  if (v.empty()) return r;
  r.lo = from_zero ? 0.0 : *std::min_element(v.begin(), v.end());
  r.hi = *std::max_element(v.begin(), v.end());
  if (r.hi - r.lo < 1e-9) {
    r.hi += 0.5;
    if (!from_zero) r.lo -= 0.5;
  }
  return r;
}

void Axes(std::ostringstream& os, const Panel& p, const std::string& title,
          const std::string& xlabel, const std::string& ylabel) {
  os << "<rect x='" << Num(p.x) << "' y='" << Num(p.y) << "' width='" << Num(p.w) << "' height='"
     << Num(p.h) << "' fill='white' stroke='#888'/>\n";
  const double xs = NiceStep(p.xr.hi - p.xr.lo, 8), ys = NiceStep(p.yr.hi - p.yr.lo, 5);
  for (double v = std::ceil(p.xr.lo / xs) * xs; v <= p.xr.hi + 1e-9 * xs; v += xs) {
    os << "<line x1='" << Num(p.X(v)) << "' y1='" << Num(p.y) << "' x2='" << Num(p.X(v)) << "' y2='"
       << Num(p.y + p.h) << "' stroke='#eee'/>"
       << "<text x='" << Num(p.X(v)) << "' y='" << Num(p.y + p.h + 14) << "' text-anchor='middle'>"
       << Label(v) << "</text>\n";
  }
  for (double v = std::ceil(p.yr.lo / ys) * ys; v <= p.yr.hi + 1e-9 * ys; v += ys) {
    os << "<line x1='" << Num(p.x) << "' y1='" << Num(p.Y(v)) << "' x2='" << Num(p.x + p.w)
       << "' y2='" << Num(p.Y(v)) << "' stroke='#eee'/>"
       << "<text x='" << Num(p.x - 6) << "' y='" << Num(p.Y(v) + 4) << "' text-anchor='end'>"
       << Label(v) << "</text>\n";
  }
  os << "<text x='" << Num(p.x) << "' y='" << Num(p.y - 10)
     << "' font-size='14' font-weight='bold'>" << Escape(title) << "</text>\n";
  os << "<text x='" << Num(p.x + p.w / 2) << "' y='" << Num(p.y + p.h + 32)
     << "' text-anchor='middle'>" << Escape(xlabel) << "</text>\n";
  os << "<text transform='translate(" << Num(p.x - 48) << "," << Num(p.y + p.h / 2)
     << ") rotate(-90)' text-anchor='middle'>" << Escape(ylabel) << "</text>\n";
}

void Polyline(std::ostringstream& os, const std::vector<std::pair<double, double>>& pts,
              const char* color, double width) {
  if (pts.empty()) return;
  os << "<polyline fill='none' stroke='" << color << "' stroke-width='" << width
     << "' stroke-linejoin='round' points='";
  for (const auto& [x, y] : pts) os << Num(x) << "," << Num(y) << " ";
  os << "'/>\n";
}

void Legend(std::ostringstream& os, double x, double y,
            const std::vector<std::pair<std::string, const char*>>& entries) {
  const double h = 18.0 * static_cast<double>(entries.size()) + 8;
  os << "<rect x='" << Num(x) << "' y='" << Num(y) << "' width='190' height='" << Num(h)
     << "' fill='white' fill-opacity='0.85' stroke='#bbb'/>\n";
  for (size_t k = 0; k < entries.size(); ++k) {
    const double yy = y + 16 + 18.0 * static_cast<double>(k);
    os << "<line x1='" << Num(x + 8) << "' y1='" << Num(yy - 4) << "' x2='" << Num(x + 32)
       << "' y2='" << Num(yy - 4) << "' stroke='" << entries[k].second << "' stroke-width='2.5'/>"
       << "<text x='" << Num(x + 38) << "' y='" << Num(yy) << "'>" << Escape(entries[k].first)
       << "</text>\n";
  }
}

}  // namespace detslam::svg
