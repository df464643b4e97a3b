#include "detslam/synth/texture.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace detslam::synth {
namespace {

int Clamp255(double v) { return static_cast<int>(std::clamp(v, 0.0, 255.0)); }

cv::Scalar Jitter(const cv::Scalar& base, double amount, Rng& rng) {
  const double common = rng.Uniform(-amount, amount);
  // One draw per declarator: the order in which a function's arguments are evaluated is
  // unspecified (gcc and clang differ). Drawn last channel first, the order gcc used when the draws
  // were arguments, so every sequence generated so far stays byte-identical.
  const double d2 = rng.Uniform(-amount, amount), d1 = rng.Uniform(-amount, amount),
               d0 = rng.Uniform(-amount, amount);
  return cv::Scalar(Clamp255(base[0] + common + d0 * 0.4), Clamp255(base[1] + common + d1 * 0.4),
                    Clamp255(base[2] + common + d2 * 0.4));
}

// A colour that differs from `base` by at least `min_contrast` gray levels (lighter or darker).
cv::Scalar Contrasting(const cv::Scalar& base, double min_contrast, double max_contrast, Rng& rng) {
  const double mean = (base[0] + base[1] + base[2]) / 3.0;
  double delta = rng.Uniform(min_contrast, max_contrast);
  if (mean + delta > 245.0 || (mean - delta > 10.0 && rng.Uniform() < 0.5)) delta = -delta;
  cv::Scalar c;
  for (int i = 0; i < 3; ++i) c[i] = Clamp255(base[i] + delta + rng.Uniform(-12, 12));
  return c;
}

cv::Scalar RandomColour(Rng& rng) {
  // Last channel first, as in Jitter.
  const int c2 = rng.UniformInt(20, 235), c1 = rng.UniformInt(20, 235), c0 = rng.UniformInt(20, 235);
  return cv::Scalar(c0, c1, c2);
}

// Smooth large-scale shading variation (dirt, uneven paint) of +-amplitude gray levels.
void AddLowFrequency(cv::Mat& img, double amplitude, Rng& rng) {
  const int gw = std::max(2, img.cols / 48), gh = std::max(2, img.rows / 48);
  cv::Mat grid(gh, gw, CV_32F);
  for (int y = 0; y < gh; ++y) {
    for (int x = 0; x < gw; ++x) grid.at<float>(y, x) = static_cast<float>(rng.Uniform(-1, 1));
  }
  cv::Mat smooth;
  cv::resize(grid, smooth, img.size(), 0, 0, cv::INTER_CUBIC);
  for (int y = 0; y < img.rows; ++y) {
    auto* row = img.ptr<cv::Vec3b>(y);
    const float* s = smooth.ptr<float>(y);
    for (int x = 0; x < img.cols; ++x) {
      const double d = amplitude * s[x];
      for (int c = 0; c < 3; ++c) row[x][c] = static_cast<uchar>(Clamp255(row[x][c] + d));
    }
  }
}

// Lines of short strokes like printed or handwritten words inside `area`.
void TextMarks(cv::Mat& img, const cv::Rect& area, const cv::Scalar& ink, Rng& rng) {
  const int line_h = std::max(3, static_cast<int>(area.height * rng.Uniform(0.04, 0.12)));
  const int stroke = std::max(1, line_h / 3);
  for (int y = area.y + line_h; y + stroke < area.y + area.height - line_h / 2;
       y += line_h + line_h / 2) {
    int x = area.x + line_h / 2;
    const int x_end =
        area.x + area.width - line_h / 2 - static_cast<int>(rng.Uniform(0, area.width * 0.3));
    while (x < x_end) {
      const int word = std::max(2, static_cast<int>(line_h * rng.Uniform(0.8, 4.0)));
      const int len = std::min(word, x_end - x);
      if (len <= 1) break;
      cv::rectangle(img, cv::Rect(x, y - stroke, len, stroke + 1), ink, cv::FILLED);
      // Ascenders and gaps so the word has corners, not just a bar.
      for (int k = 0; k < len / std::max(2, line_h / 2); ++k) {
        const int ax = x + rng.UniformInt(0, std::max(0, len - 2));
        cv::rectangle(img, cv::Rect(ax, y - line_h + stroke, std::max(1, stroke), line_h - stroke),
                      ink, cv::FILLED);
      }
      x += len + std::max(2, line_h / 2 + rng.UniformInt(0, line_h));
    }
  }
}

// Multi-scale clutter: rectangles (some with text), blobs and ticks, `per_m2` items per square
// metre at the smallest scale; larger scales get proportionally fewer items.
void Clutter(cv::Mat& img, const cv::Scalar& base, double per_m2, double min_contrast, Rng& rng) {
  const double area_m2 = img.cols * img.rows / (kTexelsPerMetre * kTexelsPerMetre);
  struct Scale {
    double min_m, max_m, density;
  };
  const Scale scales[] = {{0.15, 0.45, 0.06}, {0.04, 0.14, 0.3}, {0.012, 0.04, 1.0}};
  for (const Scale& s : scales) {
    const int count = static_cast<int>(std::ceil(per_m2 * s.density * area_m2));
    for (int i = 0; i < count; ++i) {
      const int w = std::max(2, static_cast<int>(rng.Uniform(s.min_m, s.max_m) * kTexelsPerMetre));
      const int h = std::max(2, static_cast<int>(rng.Uniform(s.min_m, s.max_m) * kTexelsPerMetre));
      const int x = rng.UniformInt(-w / 2, std::max(0, img.cols - w / 2));
      const int y = rng.UniformInt(-h / 2, std::max(0, img.rows - h / 2));
      const cv::Scalar colour =
          rng.Uniform() < 0.06 ? RandomColour(rng) : Contrasting(base, min_contrast, 75, rng);
      const double kind = rng.Uniform();
      if (kind < 0.6) {
        cv::rectangle(img, cv::Rect(x, y, w, h), colour, cv::FILLED);
        if (w > 20 && h > 20 && rng.Uniform() < 0.6) {
          TextMarks(img, cv::Rect(x, y, w, h), Contrasting(colour, 50, 120, rng), rng);
        }
      } else if (kind < 0.85) {
        cv::ellipse(img, cv::Point(x + w / 2, y + h / 2), cv::Size(w / 2, h / 2),
                    rng.Uniform(0, 180), 0, 360, colour, cv::FILLED, cv::LINE_AA);
      } else {
        const cv::Point a(x, y), b(x + w * (rng.Uniform() < 0.5 ? 1 : -1), y + h);
        cv::line(img, a, b, colour, std::max(1, std::min(w, h) / 8), cv::LINE_AA);
      }
    }
  }
}

void Grain(cv::Mat& img, double amplitude, Rng& rng) {
  cv::Mat noise(img.size(), CV_8UC3);
  cv::RNG local(rng.NextU64());  // seeded from our Rng, never OpenCV's global generator
  local.fill(noise, cv::RNG::NORMAL, cv::Scalar::all(128), cv::Scalar::all(amplitude));
  cv::addWeighted(img, 1.0, noise, 1.0, -128.0, img);
}

}  // namespace

float InfraredGain(SurfaceKind kind) {
  switch (kind) {
    case SurfaceKind::kWindow:
      return 0.f;
    case SurfaceKind::kScreen:
      return 0.6f;
    default:
      return 1.f;
  }
}

cv::Mat MakeSurfaceTexture(SurfaceKind kind, int width_px, int height_px, Rng& rng,
                           const TextureStyle& style) {
  const double room = style.room_clutter;
  const int w = std::max(2, width_px), h = std::max(2, height_px);
  cv::Mat img;
  cv::Scalar base;
  switch (kind) {
    case SurfaceKind::kWall:
      base = Jitter(cv::Scalar(170, 190, 200), 25, rng);
      break;
    case SurfaceKind::kFloor:
      base = Jitter(cv::Scalar(90, 95, 100), 20, rng);
      break;
    case SurfaceKind::kCeiling:
      base = Jitter(cv::Scalar(215, 218, 220), 8, rng);
      break;
    case SurfaceKind::kWood:
      base = Jitter(cv::Scalar(70, 120, 165), 25, rng);
      break;
    case SurfaceKind::kCardboard:
      base = Jitter(cv::Scalar(95, 145, 185), 15, rng);
      break;
    case SurfaceKind::kPoster:
      base = RandomColour(rng);
      break;
    case SurfaceKind::kBooks:
      base = Jitter(cv::Scalar(60, 60, 60), 20, rng);
      break;
    case SurfaceKind::kMetal:
      base = Jitter(cv::Scalar(140, 140, 135), 30, rng);
      break;
    case SurfaceKind::kScreen:
      base = Jitter(cv::Scalar(35, 30, 30), 10, rng);
      break;
    case SurfaceKind::kPlainWall:
      base = Jitter(cv::Scalar(175, 192, 200), 15, rng);
      break;
    case SurfaceKind::kWindow:
      base = Jitter(cv::Scalar(235, 222, 205), 10, rng);
      break;
  }
  img = cv::Mat(h, w, CV_8UC3, base);
  const double m = kTexelsPerMetre;
  switch (kind) {
    case SurfaceKind::kWall:
      AddLowFrequency(img, 12, rng);
      Clutter(img, base, 150 * room, 30, rng);
      break;
    case SurfaceKind::kFloor: {
      const int tile = static_cast<int>(0.5 * m);
      for (int y = 0; y < h; y += tile) {
        for (int x = 0; x < w; x += tile) {
          cv::rectangle(img, cv::Rect(x, y, tile, tile), Jitter(base, 28, rng), cv::FILLED);
        }
      }
      Clutter(img, base, 110 * room, 30, rng);
      break;
    }
    case SurfaceKind::kCeiling: {
      const int tile = static_cast<int>(0.6 * m);
      for (int y = 0; y < h; y += tile) {
        for (int x = 0; x < w; x += tile) {
          const bool light = rng.Uniform() < 0.15;
          cv::rectangle(img, cv::Rect(x, y, tile, tile),
                        light ? cv::Scalar(250, 250, 250) : Jitter(base, 15, rng), cv::FILLED);
          cv::rectangle(img, cv::Rect(x, y, tile, tile), Contrasting(base, 40, 70, rng), 2);
        }
      }
      Clutter(img, base, 80 * room, 30, rng);
      break;
    }
    case SurfaceKind::kWood:
      for (int i = 0; i < h / 3; ++i) {
        const int y = rng.UniformInt(0, h - 1);
        cv::line(img, cv::Point(0, y), cv::Point(w - 1, y + rng.UniformInt(-6, 6)),
                 Jitter(base, 25, rng), 1, cv::LINE_AA);
      }
      Clutter(img, base, 150, 35, rng);
      break;
    case SurfaceKind::kCardboard:
      Clutter(img, base, 90, 35, rng);
      cv::rectangle(img,
                    cv::Rect(0, h / 2 - static_cast<int>(0.025 * m), w, static_cast<int>(0.05 * m)),
                    Jitter(cv::Scalar(150, 170, 180), 20, rng), cv::FILLED);
      TextMarks(img, cv::Rect(w / 8, h / 8, w / 2, h / 4), cv::Scalar(30, 30, 30), rng);
      break;
    case SurfaceKind::kPoster:
      Clutter(img, base, 350, 40, rng);
      TextMarks(img, cv::Rect(w / 10, h * 6 / 10, w * 8 / 10, h * 3 / 10),
                Contrasting(base, 80, 140, rng), rng);
      break;
    case SurfaceKind::kBooks: {
      int x = 0;
      while (x < w) {
        const int bw = std::max(3, static_cast<int>(rng.Uniform(0.015, 0.06) * m));
        const int top = static_cast<int>(rng.Uniform(0.0, 0.35) * h);
        const cv::Scalar c = RandomColour(rng);
        cv::rectangle(img, cv::Rect(x, top, bw, h - top), c, cv::FILLED);
        if (bw > 6)
          TextMarks(img, cv::Rect(x, top + h / 5, bw, h / 2), Contrasting(c, 60, 120, rng), rng);
        x += bw + rng.UniformInt(0, 3);
      }
      break;
    }
    case SurfaceKind::kMetal:
      AddLowFrequency(img, 15, rng);
      Clutter(img, base, 100, 35, rng);
      break;
    case SurfaceKind::kScreen:
      Clutter(img, base, 500, 60, rng);
      break;
    case SurfaceKind::kPlainWall:
      AddLowFrequency(img, 10, rng);
      Clutter(img, base, 8 * room, 25, rng);
      break;
    case SurfaceKind::kWindow: {
      // The view outside, out of focus: a few soft darker shapes (buildings, trees) on a bright
      // sky, then the frames: a border and mullions every 0.6-1.0 m.
      const int shapes = std::max(1, static_cast<int>(w / m * 2));
      for (int i = 0; i < shapes; ++i) {
        const int bw = static_cast<int>(rng.Uniform(0.2, 0.8) * m);
        const int top = static_cast<int>(rng.Uniform(0.3, 0.8) * h);
        cv::rectangle(img, cv::Rect(rng.UniformInt(0, w - 1) - bw / 2, top, bw, h - top),
                      Jitter(cv::Scalar(150, 160, 165), 25, rng), cv::FILLED);
      }
      cv::GaussianBlur(img, img, cv::Size(0, 0), 0.06 * m);
      const cv::Scalar frame = Jitter(cv::Scalar(80, 80, 85), 15, rng);
      const int bar = std::max(2, static_cast<int>(0.035 * m));
      cv::rectangle(img, cv::Rect(0, 0, w, h), frame, 2 * bar);
      const double step = rng.Uniform(0.6, 1.0) * m;
      for (double x = step; x < w - step / 2; x += step)
        cv::rectangle(img, cv::Rect(static_cast<int>(x) - bar / 2, 0, bar, h), frame, cv::FILLED);
      break;
    }
  }
  Grain(img, 3.0, rng);
  return img;
}

}  // namespace detslam::synth
