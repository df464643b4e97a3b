#include "detslam/synth/people.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "detslam/core/check.h"
#include "detslam/core/math.h"
#include "detslam/core/rng.h"
#include "detslam/synth/options.h"

namespace detslam::synth {
namespace {

cv::Scalar RandomCloth(Rng& rng) {
  // One draw per declarator: the order in which a function's arguments are evaluated is
  // unspecified (gcc and clang differ). Drawn last channel first, the order gcc used when the draws
  // were arguments, so every sequence generated so far stays byte-identical.
  const int c2 = rng.UniformInt(20, 220), c1 = rng.UniformInt(20, 220), c0 = rng.UniformInt(20, 220);
  return cv::Scalar(c0, c1, c2);
}

// A clothing texture: plaid or stripes with fabric noise.
cv::Mat ClothTexture(cv::Size size, Rng& rng) {
  const cv::Scalar a = RandomCloth(rng), b = RandomCloth(rng);
  cv::Mat tex(size, CV_8UC3, a);
  const int step = rng.UniformInt(8, 22);
  const bool plaid = rng.Uniform() < 0.6;
  for (int x = rng.UniformInt(0, step); x < size.width; x += step) {
    cv::rectangle(tex, cv::Rect(x, 0, std::max(2, step / 3), size.height), b, cv::FILLED);
  }
  if (plaid) {
    for (int y = rng.UniformInt(0, step); y < size.height; y += step) {
      cv::rectangle(tex, cv::Rect(0, y, size.width, std::max(2, step / 3)), b * 0.7, cv::FILLED);
    }
  }
  cv::Mat noise(size, CV_8UC3);
  cv::RNG local(rng.NextU64());
  local.fill(noise, cv::RNG::NORMAL, cv::Scalar::all(128), cv::Scalar::all(8));
  cv::addWeighted(tex, 1.0, noise, 1.0, -128.0, tex);
  return tex;
}

void Limb(cv::Mat& mask, cv::Point2d top, double angle, double length, int thickness) {
  const cv::Point2d end = top + length * cv::Point2d(std::sin(angle), std::cos(angle));
  cv::line(mask, top, end, cv::Scalar(255), thickness, cv::LINE_AA);
}

// Integral of |cos| from 0 to x (the distance travelled by sin, in amplitudes): monotonic.
double PathLengthOfSine(double x) {
  const double turns = std::floor(x / (2.0 * kPi));
  const double r = x - turns * 2.0 * kPi;
  double g;
  if (r < 0.5 * kPi) {
    g = std::sin(r);
  } else if (r < 1.5 * kPi) {
    g = 2.0 - std::sin(r);
  } else {
    g = 4.0 + std::sin(r);
  }
  return 4.0 * turns + g;
}

}  // namespace

void ComputeSilhouetteRows(Sprite* sprite) {
  const cv::Mat& a = sprite->alpha;
  sprite->row_mid.assign(a.rows, -1.f);
  sprite->row_half.assign(a.rows, 0.f);
  for (int y = 0; y < a.rows; ++y) {
    const uchar* row = a.ptr<uchar>(y);
    int lo = -1, hi = -1;
    for (int x = 0; x < a.cols; ++x) {
      if (row[x] > 127) {
        if (lo < 0) lo = x;
        hi = x;
      }
    }
    if (lo >= 0) {
      sprite->row_mid[y] = 0.5f * (lo + hi);
      sprite->row_half[y] = 0.5f * (hi - lo) + 1.0f;
    }
  }
}

Sprite SwingLegs(const Sprite& photo, double angle) {
  const int h = photo.alpha.rows, w = photo.alpha.cols;
  const int hip = static_cast<int>(0.6 * h);
  float mid = photo.row_mid[hip];
  if (mid < 0) mid = 0.5f * w;
  Sprite out;
  out.bgr = cv::Mat(h, w, CV_8UC3, cv::Scalar::all(0));
  out.alpha = cv::Mat(h, w, CV_8U, cv::Scalar(0));
  photo.bgr.rowRange(0, hip).copyTo(out.bgr.rowRange(0, hip));
  photo.alpha.rowRange(0, hip).copyTo(out.alpha.rowRange(0, hip));
  // Each leg: pixels of its side below the hip, rotated about its joint (a quarter of the hip
  // width from the middle); the destination takes whichever leg covers it, the forward one first.
  const float joint_dx = 0.5f * std::max(1.f, photo.row_half[hip]);
  const double a[2] = {angle, -angle};  // left, right leg
  const int order[2] = {angle >= 0 ? 0 : 1, angle >= 0 ? 1 : 0};
  for (int y = hip; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (int leg : order) {
        const float jx = leg == 0 ? mid - joint_dx : mid + joint_dx;
        const double c = std::cos(a[leg]), s = std::sin(a[leg]);
        // Inverse rotation of (x, y) about the joint (jx, hip).
        const double dx = x - jx, dy = y - hip;
        const double sx = jx + c * dx + s * dy, sy = hip - s * dx + c * dy;
        const int ix = static_cast<int>(std::lround(sx)), iy = static_cast<int>(std::lround(sy));
        if (ix < 0 || iy < hip || ix >= w || iy >= h) continue;
        if ((leg == 0) != (ix < mid)) continue;  // a pixel of the other leg
        if (photo.alpha.at<uchar>(iy, ix) <= 127) continue;
        out.bgr.at<cv::Vec3b>(y, x) = photo.bgr.at<cv::Vec3b>(iy, ix);
        out.alpha.at<uchar>(y, x) = 255;
        break;
      }
    }
  }
  ComputeSilhouetteRows(&out);
  return out;
}

std::vector<PersonLook> LoadPhotoPeople(const std::string& dir, int gait_phases) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw InputError(dir, 0, "people folder does not exist");
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (entry.path().extension() == ".png") files.push_back(entry.path().string());
  }
  std::sort(files.begin(), files.end());
  if (files.empty()) throw InputError(dir, 0, "people folder has no *.png cut-outs");
  std::vector<PersonLook> looks;
  for (const auto& file : files) {
    const cv::Mat rgba = cv::imread(file, cv::IMREAD_UNCHANGED);
    if (rgba.empty()) throw InputError(file, 0, "cannot read PNG");
    if (rgba.channels() != 4) {
      throw InputError(file, 0,
                       "person cut-out has no alpha channel (need RGBA, alpha = silhouette)");
    }
    cv::Mat rgba8 = rgba;
    if (rgba.depth() == CV_16U) rgba.convertTo(rgba8, CV_8U, 1.0 / 257.0);
    std::vector<cv::Mat> ch;
    cv::split(rgba8, ch);
    const cv::Rect bbox = cv::boundingRect(ch[3] > 127);
    if (bbox.area() < 100) throw InputError(file, 0, "alpha silhouette is (nearly) empty");
    Sprite s;
    cv::merge(std::vector<cv::Mat>{ch[0], ch[1], ch[2]}, s.bgr);
    s.bgr = s.bgr(bbox).clone();
    s.alpha = ch[3](bbox).clone();
    ComputeSilhouetteRows(&s);
    PersonLook look;
    for (int p = 1; p < gait_phases; ++p)  // phase 0 is the photo, then one swing cycle
      look.gait.push_back(SwingLegs(s, 0.3 * std::sin(2.0 * kPi * p / gait_phases)));
    look.gait.insert(look.gait.begin(), std::move(s));
    looks.push_back(std::move(look));
  }
  return looks;
}

PersonLook MakeProceduralPerson(uint64_t seed, int phases) {
  Rng rng(seed ^ 0x9E0F1EULL);
  const int w = 200, h = 480;  // aspect of a person with arms at the sides (~0.7 m x 1.7 m)
  const cv::Mat shirt = ClothTexture(cv::Size(w, h), rng);
  const cv::Mat pants = ClothTexture(cv::Size(w, h), rng) * 0.55;
  const int skin_r = rng.UniformInt(150, 220), skin_g = rng.UniformInt(100, 170),
            skin_b = rng.UniformInt(60, 150);  // last channel first, as in RandomCloth
  const cv::Scalar skin(skin_b, skin_g, skin_r);
  const cv::Scalar hair = RandomCloth(rng) * 0.35;
  const cv::Scalar shoes = RandomCloth(rng) * 0.3;
  const double shoulder = rng.Uniform(0.2, 0.24) * w;
  PersonLook look;
  for (int k = 0; k < phases; ++k) {
    const double swing = 0.35 * std::sin(2.0 * kPi * k / phases);
    cv::Mat m_shirt = cv::Mat::zeros(h, w, CV_8U), m_pants = m_shirt.clone();
    cv::Mat m_skin = m_shirt.clone(), m_hair = m_shirt.clone(), m_shoes = m_shirt.clone();
    const double cx = w / 2.0;
    // Legs (hip at 0.52 h), shoes at their ends.
    for (int side : {-1, 1}) {
      const cv::Point2d hip(cx + side * 0.09 * w, 0.53 * h);
      const double a = side * swing;
      Limb(m_pants, hip, a, 0.43 * h, static_cast<int>(0.12 * w));
      const cv::Point2d foot = hip + 0.43 * h * cv::Point2d(std::sin(a), std::cos(a));
      cv::ellipse(m_shoes, foot + cv::Point2d(3, 0), cv::Size(static_cast<int>(0.08 * w), 7), 0, 0,
                  360, cv::Scalar(255), cv::FILLED, cv::LINE_AA);
    }
    cv::rectangle(m_pants,
                  cv::Rect(static_cast<int>(cx - 0.16 * w), static_cast<int>(0.5 * h),
                           static_cast<int>(0.32 * w), static_cast<int>(0.08 * h)),
                  cv::Scalar(255), cv::FILLED);
    // Torso.
    std::vector<cv::Point> torso = {
        cv::Point(static_cast<int>(cx - shoulder), static_cast<int>(0.17 * h)),
        cv::Point(static_cast<int>(cx + shoulder), static_cast<int>(0.17 * h)),
        cv::Point(static_cast<int>(cx + 0.17 * w), static_cast<int>(0.54 * h)),
        cv::Point(static_cast<int>(cx - 0.17 * w), static_cast<int>(0.54 * h))};
    cv::fillConvexPoly(m_shirt, torso, cv::Scalar(255), cv::LINE_AA);
    // Arms swing against the legs; hands are skin.
    for (int side : {-1, 1}) {
      const cv::Point2d sh(cx + side * (shoulder - 6), 0.19 * h);
      const double a = -side * swing * 0.8 + side * 0.06;
      Limb(m_shirt, sh, a, 0.3 * h, static_cast<int>(0.085 * w));
      const cv::Point2d hand = sh + 0.33 * h * cv::Point2d(std::sin(a), std::cos(a));
      cv::circle(m_skin, hand, static_cast<int>(0.045 * w), cv::Scalar(255), cv::FILLED,
                 cv::LINE_AA);
    }
    // Neck, head, hair.
    cv::rectangle(m_skin,
                  cv::Rect(static_cast<int>(cx - 0.05 * w), static_cast<int>(0.12 * h),
                           static_cast<int>(0.1 * w), static_cast<int>(0.06 * h)),
                  cv::Scalar(255), cv::FILLED);
    cv::ellipse(m_skin, cv::Point2d(cx, 0.075 * h), cv::Size(static_cast<int>(0.11 * w), 0.065 * h),
                0, 0, 360, cv::Scalar(255), cv::FILLED, cv::LINE_AA);
    cv::ellipse(m_hair, cv::Point2d(cx, 0.05 * h), cv::Size(static_cast<int>(0.115 * w), 0.045 * h),
                0, 180, 360, cv::Scalar(255), cv::FILLED, cv::LINE_AA);
    Sprite s;
    s.bgr = cv::Mat(h, w, CV_8UC3, cv::Scalar(0, 0, 0));
    shirt.copyTo(s.bgr, m_shirt);
    pants.copyTo(s.bgr, m_pants);
    s.bgr.setTo(skin, m_skin);
    s.bgr.setTo(hair, m_hair);
    s.bgr.setTo(shoes, m_shoes);
    s.alpha = (m_shirt | m_pants | m_skin | m_hair | m_shoes);
    cv::threshold(s.alpha, s.alpha, 127, 255, cv::THRESH_BINARY);
    ComputeSilhouetteRows(&s);
    look.gait.push_back(std::move(s));
  }
  return look;
}

PeopleScript::PeopleScript(const std::string& preset, uint64_t seed, bool realistic)
    : realistic_(realistic) {
  RequireSynthPreset(preset);
  Rng rng(seed ^ 0x9E091EULL);
  auto phase = [&] { return rng.Uniform(0.0, 2.0 * kPi); };
  if (preset == "static") return;
  if (preset == "sitting_static") {
    // Two people sitting behind the far edge of the table, facing the camera.
    walkers_.push_back({{-0.5, 2.15}, {1, 0}, 0.05, 6.0, phase(), 0.03, 1.32, true});
    walkers_.push_back({{0.55, 2.18}, {1, 0}, 0.06, 7.5, phase(), 0.03, 1.28, true});
    return;
  }
  if (preset == "loop_long") {
    // One person strolling between the loop and the far wall.
    walkers_.push_back({{0.0, 3.2}, {1, 0}, 3.0, 26.0, phase(), 0.15, 1.72, false});
    return;
  }
  if (preset == "lookalike") {
    // One person in front of each part of the room.
    walkers_.push_back({{-3.4, 1.3}, {1, 0.05}, 1.4, 13.0, phase(), 0.12, 1.74, false});
    walkers_.push_back({{3.4, 1.2}, {1, -0.05}, 1.4, 15.0, phase(), 0.10, 1.68, false});
    for (auto& w : walkers_) w.axis.normalize();
    return;
  }
  if (preset == "roam") {
    // One person strolling behind the central desk, seen when the camera faces the front.
    walkers_.push_back({{0.2, 2.1}, {1, 0}, 1.0, 16.0, phase(), 0.08, 1.70, false});
    return;
  }
  if (preset == "loop") {
    // One person strolling along the far side of the room, behind the central desk (y 2.1; the
    // desk spans y 0.6-1.9, the camera's circuit y -1.6..0.4, so they never meet: earlier the
    // person walked at y 0.3, across the circuit, and on some seeds filled the view from a few
    // centimetres, which no camera operator would let happen).
    walkers_.push_back({{0.0, 2.1}, {1, 0}, 1.2, 18.0, phase(), 0.08, 1.72, false});
    return;
  }
  if (realistic) {
    // Walking presets, realistic: one person walks diagonally from beside the table to about
    // 1 m in front of the camera's resting place (0, -1.6) and back (0.6-0.7 m where the camera
    // moves towards them, as in walking_xyz); the other crosses the view behind them with the
    // same period, so that they pass in front of each other twice a cycle.
    walkers_.push_back({{0.075, -0.204}, {0.45, -0.89}, 0.5, 12.0, phase(), 0.08, 1.74, false});
    walkers_.push_back({{0.1, 0.35}, {-1, 0.1}, 1.3, 12.0, walkers_[0].phase + 0.5 * kPi, 0.10,
                        1.68, false});
    for (auto& w : walkers_) w.axis.normalize();
    return;
  }
  // Walking presets: two people crossing the view back and forth in front of the table
  // (1.3-2.2 m from the camera), at up to ~1 m/s, leaving and re-entering the view.
  walkers_.push_back({{0.0, -0.25}, {1, 0.08}, 1.2, 11.0, phase(), 0.12, 1.74, false});
  walkers_.push_back({{0.1, 0.25}, {-1, 0.15}, 1.3, 14.0, phase(), 0.10, 1.68, false});
  for (auto& w : walkers_) w.axis.normalize();
}

std::vector<PersonState> PeopleScript::At(double t) const {
  std::vector<PersonState> out;
  for (size_t i = 0; i < walkers_.size(); ++i) {
    const Walker& w = walkers_[i];
    const double arg = 2.0 * kPi * t / w.period + w.phase;
    const double along = w.amplitude * std::sin(arg);
    const Eigen::Vector2d side(-w.axis.y(), w.axis.x());
    const Eigen::Vector2d xy =
        w.centre + along * w.axis + w.sway * std::sin(0.5 * arg + 1.0) * side;
    PersonState s;
    s.id = static_cast<int>(i) + 1;
    s.look = static_cast<int>(i);
    s.height = w.height;
    double bob = 0.0;
    if (!w.sitting) {
      // Gait phase from the distance walked (~1.3 m per stride cycle), a slight vertical bob.
      const double walked = w.amplitude * PathLengthOfSine(arg);
      const double cycle = walked / 1.3;
      s.gait_phase = static_cast<int>(std::floor((cycle - std::floor(cycle)) * 8.0)) % 8;
      bob = 0.015 * std::abs(std::sin(2.0 * kPi * cycle));
    } else {
      bob = 0.01 * std::sin(1.7 * arg);
    }
    s.foot = Eigen::Vector3d(xy.x(), xy.y(), bob);
    if (realistic_ && !w.sitting) {
      // Facing the walking direction, turning round at each end of the walk within about a
      // tenth of the period: yaw from the axis (forward) to the axis + pi (back), through the
      // side in between.
      const double forward = std::tanh(4.0 * std::cos(arg));  // +1 walking along the axis
      s.has_facing = true;
      s.facing_yaw = std::atan2(w.axis.y(), w.axis.x()) + 0.5 * kPi * (1.0 - forward);
    }
    out.push_back(s);
  }
  return out;
}

}  // namespace detslam::synth
