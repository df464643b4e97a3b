// Small drawing helpers shared by the SVG figures of eval/ (svg_plot.cc, run_report.cc): number
// formatting, XML escaping, tick steps, data ranges, plot panels with axes, polylines, legends.
#pragma once

#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace detslam::svg {

std::string Num(double v);                 // coordinate, 2 decimals
std::string Label(double v);               // tick label (%g, no "-0")
std::string Escape(const std::string& s);  // text for XML/HTML (&, <, >, ', ")
// Tick step of 1, 2 or 5 times a power of ten giving about `target` ticks over `span`.
double NiceStep(double span, int target);

struct Range {
  double lo = 0, hi = 1;
  void Include(double v);
  // The range of `v` (from 0 when `from_zero`); a degenerate range is widened to span 0.5 or 1.
  static Range Of(const std::vector<double>& v, bool from_zero);
};

// A plotting rectangle with data ranges; y grows upwards in data space.
struct Panel {
  double x, y, w, h;
  Range xr, yr;
  double X(double v) const { return x + (v - xr.lo) / (xr.hi - xr.lo) * w; }
  double Y(double v) const { return y + h - (v - yr.lo) / (yr.hi - yr.lo) * h; }
  double Y2(double v, const Range& r) const { return y + h - (v - r.lo) / (r.hi - r.lo) * h; }
};

// Frame, grid, tick labels, title and axis labels of a panel.
void Axes(std::ostringstream& os, const Panel& p, const std::string& title,
          const std::string& xlabel, const std::string& ylabel);
void Polyline(std::ostringstream& os, const std::vector<std::pair<double, double>>& pts,
              const char* color, double width);
void Legend(std::ostringstream& os, double x, double y,
            const std::vector<std::pair<std::string, const char*>>& entries);

}  // namespace detslam::svg
