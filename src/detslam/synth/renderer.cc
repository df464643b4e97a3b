#include "detslam/synth/renderer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core/utility.hpp>

namespace detslam::synth {
namespace {

using Vec3 = Eigen::Vector3f;

struct PixelRect {
  int u0 = 0, v0 = 0, u1 = -1, v1 = -1;  // inclusive; empty if u1 < u0
  bool Contains(int u, int v) const { return u >= u0 && u <= u1 && v >= v0 && v <= v1; }
};

// Image rectangle covered by the convex hull of `pts` clipped to the near plane: the projections
// of the points in front of the camera plus the near-plane crossings of the segments between
// every pair of points (a superset of the hull's edges). Empty if nothing is in front.
PixelRect ProjectBounds(const std::vector<Vec3>& pts, const Eigen::Matrix3f& cam_r,
                        const Vec3& cam_t, const PinholeCamera& cam) {
  constexpr float kNear = 0.02f;
  std::vector<Vec3> q;
  for (const Vec3& p : pts) q.push_back(cam_r * p + cam_t);
  std::vector<Vec3> front;
  for (size_t i = 0; i < q.size(); ++i) {
    if (q[i].z() >= kNear) front.push_back(q[i]);
    for (size_t j = i + 1; j < q.size(); ++j) {
      if ((q[i].z() < kNear) != (q[j].z() < kNear)) {
        const float s = (kNear - q[i].z()) / (q[j].z() - q[i].z());
        front.push_back(q[i] + s * (q[j] - q[i]));
      }
    }
  }
  PixelRect r;
  if (front.empty()) return r;
  float umin = 1e9f, umax = -1e9f, vmin = 1e9f, vmax = -1e9f;
  for (const Vec3& p : front) {
    const float u = static_cast<float>(cam.fx) * p.x() / p.z() + static_cast<float>(cam.cx);
    const float v = static_cast<float>(cam.fy) * p.y() / p.z() + static_cast<float>(cam.cy);
    umin = std::min(umin, u);
    umax = std::max(umax, u);
    vmin = std::min(vmin, v);
    vmax = std::max(vmax, v);
  }
  r.u0 = static_cast<int>(std::clamp(std::floor(umin) - 1.f, 0.f, static_cast<float>(cam.width)));
  r.v0 = static_cast<int>(std::clamp(std::floor(vmin) - 1.f, 0.f, static_cast<float>(cam.height)));
  r.u1 = static_cast<int>(std::clamp(std::ceil(umax) + 1.f, -1.f, cam.width - 1.f));
  r.v1 = static_cast<int>(std::clamp(std::ceil(vmax) + 1.f, -1.f, cam.height - 1.f));
  return r;
}

inline cv::Vec3f Bilinear(const cv::Mat& tex, float col, float row) {
  col = std::clamp(col - 0.5f, 0.f, static_cast<float>(tex.cols - 1));
  row = std::clamp(row - 0.5f, 0.f, static_cast<float>(tex.rows - 1));
  const int c0 = static_cast<int>(col), r0 = static_cast<int>(row);
  const int c1 = std::min(c0 + 1, tex.cols - 1), r1 = std::min(r0 + 1, tex.rows - 1);
  const float fc = col - c0, fr = row - r0;
  const cv::Vec3b* a = tex.ptr<cv::Vec3b>(r0);
  const cv::Vec3b* b = tex.ptr<cv::Vec3b>(r1);
  cv::Vec3f out;
  for (int k = 0; k < 3; ++k) {
    const float top = a[c0][k] + fc * (a[c1][k] - a[c0][k]);
    const float bot = b[c0][k] + fc * (b[c1][k] - b[c0][k]);
    out[k] = top + fr * (bot - top);
  }
  return out;
}

struct Billboard {
  int id = 0;
  const Sprite* sprite = nullptr;
  Vec3 foot, normal, right, up{0.f, 0.f, 1.f};
  float width = 0, height = 0, bulge = 0;
  bool mirrored = false;  // seen from behind: the sprite mirrored
  PixelRect rect;
};

}  // namespace

IdealFrame RenderIdeal(const Scene& scene, const std::vector<PersonLook>& looks,
                       const std::vector<PersonState>& people, const PinholeCamera& camera,
                       const Rigid3d& world_from_cam) {
  const int w = camera.width, h = camera.height;
  IdealFrame out{cv::Mat(h, w, CV_8UC3), cv::Mat(h, w, CV_32F), cv::Mat(h, w, CV_16U),
                 cv::Mat(h, w, CV_8U)};
  RenderIdealRows(scene, looks, people, camera, world_from_cam, 0, h, &out);
  return out;
}

void RenderIdealRows(const Scene& scene, const std::vector<PersonLook>& looks,
                     const std::vector<PersonState>& people, const PinholeCamera& camera,
                     const Rigid3d& world_from_cam, int v_begin, int v_end, IdealFrame* out_ptr) {
  const int w = camera.width, h = camera.height;
  IdealFrame& out = *out_ptr;
  CV_Assert(out.bgr.type() == CV_8UC3 && out.bgr.cols == w && out.bgr.rows == h);
  CV_Assert(out.depth.type() == CV_32F && out.depth.size() == out.bgr.size());
  CV_Assert(out.ids.type() == CV_16U && out.ids.size() == out.bgr.size());
  const bool with_ir = !out.ir.empty();
  CV_Assert(!with_ir || (out.ir.type() == CV_8U && out.ir.size() == out.bgr.size()));
  v_begin = std::clamp(v_begin, 0, h);
  v_end = std::clamp(v_end, v_begin, h);
  const Eigen::Matrix3f r_wc = world_from_cam.RotationMatrix().cast<float>();
  const Vec3 c = world_from_cam.translation().cast<float>();
  const Eigen::Matrix3f r_cw = r_wc.transpose();
  const Vec3 t_cw = -(r_cw * c);

  // Per-frame culling: the image rectangle each box can cover.
  std::vector<PixelRect> box_rects(scene.boxes.size());
  for (size_t i = 0; i < scene.boxes.size(); ++i) {
    const SceneBox& b = scene.boxes[i];
    if (b.interior) {
      box_rects[i] = PixelRect{0, 0, w - 1, h - 1};
      continue;
    }
    std::vector<Vec3> corners;
    for (int k = 0; k < 8; ++k) {
      corners.emplace_back(k & 1 ? b.hi.x() : b.lo.x(), k & 2 ? b.hi.y() : b.lo.y(),
                           k & 4 ? b.hi.z() : b.lo.z());
    }
    box_rects[i] = ProjectBounds(corners, r_cw, t_cw, camera);
  }
  // People billboards, turned to face the camera.
  std::vector<Billboard> boards;
  for (const PersonState& p : people) {
    const PersonLook& look = looks.at(static_cast<size_t>(p.look) % looks.size());
    Billboard bb;
    bb.id = p.id;
    bb.sprite = &look.gait[static_cast<size_t>(p.gait_phase) % look.gait.size()];
    bb.foot = p.foot.cast<float>();
    Vec3 to_cam = c - bb.foot;
    to_cam.z() = 0.f;
    if (to_cam.norm() < 0.05f) continue;
    bb.normal = to_cam.normalized();
    bb.right = bb.up.cross(bb.normal);
    bb.height = static_cast<float>(p.height);
    bb.width = bb.height * bb.sprite->bgr.cols / static_cast<float>(bb.sprite->bgr.rows);
    if (p.has_facing) {
      // A body about 0.55 times as deep as it is wide, seen at angle beta from its front.
      const Vec3 facing(static_cast<float>(std::cos(p.facing_yaw)),
                        static_cast<float>(std::sin(p.facing_yaw)), 0.f);
      const float cb = facing.dot(bb.normal), sb = std::sqrt(std::max(0.f, 1.f - cb * cb));
      bb.width *= std::min(1.f, std::abs(cb) + 0.55f * sb);
      bb.mirrored = cb < 0.f;
    }
    bb.bulge = static_cast<float>(p.depth_bulge);
    std::vector<Vec3> corners;
    for (float s : {-0.5f, 0.5f}) {
      for (float z : {0.f, 1.f}) {
        for (float n : {0.f, 1.f}) {
          corners.push_back(bb.foot + s * bb.width * bb.right + z * bb.height * bb.up +
                            n * bb.bulge * bb.normal);
        }
      }
    }
    bb.rect = ProjectBounds(corners, r_cw, t_cw, camera);
    if (bb.rect.u1 >= bb.rect.u0) boards.push_back(bb);
  }

  const float fx = static_cast<float>(camera.fx), fy = static_cast<float>(camera.fy);
  const float cx = static_cast<float>(camera.cx), cy = static_cast<float>(camera.cy);
  const float kInf = std::numeric_limits<float>::infinity();
  constexpr int kRowBlock = 8;
  const int blocks = (v_end - v_begin + kRowBlock - 1) / kRowBlock;
  cv::parallel_for_(cv::Range(0, blocks), [&](const cv::Range& range) {
    std::vector<int> row_boxes;
    for (int blk = range.start; blk < range.end; ++blk) {
      for (int v = v_begin + blk * kRowBlock; v < std::min(v_end, v_begin + (blk + 1) * kRowBlock);
           ++v) {
        row_boxes.clear();
        for (size_t i = 0; i < box_rects.size(); ++i) {
          if (v >= box_rects[i].v0 && v <= box_rects[i].v1) row_boxes.push_back(static_cast<int>(i));
        }
        cv::Vec3b* rgb = out.bgr.ptr<cv::Vec3b>(v);
        float* dep = out.depth.ptr<float>(v);
        uint16_t* ids = out.ids.ptr<uint16_t>(v);
        uchar* irs = with_ir ? out.ir.ptr<uchar>(v) : nullptr;
        for (int u = 0; u < w; ++u) {
          const Vec3 d = r_wc * Vec3((u + 0.f - cx) / fx, (v + 0.f - cy) / fy, 1.f);
          const Vec3 inv(1.f / d.x(), 1.f / d.y(), 1.f / d.z());
          float best_t = kInf;
          int best_box = -1, best_axis = 0;
          bool best_hi = false;
          for (int bi : row_boxes) {
            if (u < box_rects[bi].u0 || u > box_rects[bi].u1) continue;
            const SceneBox& b = scene.boxes[bi];
            float tnear = -kInf, tfar = kInf;
            int near_axis = 0, far_axis = 0;
            for (int a = 0; a < 3; ++a) {
              float t1 = (b.lo[a] - c[a]) * inv[a], t2 = (b.hi[a] - c[a]) * inv[a];
              if (t1 > t2) std::swap(t1, t2);
              if (t1 > tnear) { tnear = t1; near_axis = a; }
              if (t2 < tfar) { tfar = t2; far_axis = a; }
            }
            if (tnear > tfar) continue;
            if (b.interior) {
              if (tfar > 0.f && tfar < best_t) {
                best_t = tfar; best_box = bi; best_axis = far_axis; best_hi = d[far_axis] > 0.f;
              }
            } else if (tnear > 1e-4f && tnear < best_t) {
              best_t = tnear; best_box = bi; best_axis = near_axis; best_hi = d[near_axis] < 0.f;
            }
          }
          cv::Vec3f colour(0.f, 0.f, 0.f);
          float ir_level = 0.f;
          uint16_t id = 0;
          if (best_box >= 0) {
            const SceneBox& b = scene.boxes[best_box];
            id = b.instance;
            const Vec3 p = c + best_t * d;
            float col, row;
            FaceTexel(b, best_axis, p, &col, &row);
            const int tex = b.texture[FaceIndex(best_axis, best_hi)];
            colour = Bilinear(scene.textures[tex], col, row);
            if (with_ir) {
              const float gain =
                  static_cast<size_t>(tex) < scene.ir_gain.size() ? scene.ir_gain[tex] : 1.f;
              ir_level = gain * (0.114f * colour[0] + 0.587f * colour[1] + 0.299f * colour[2]);
            }
            Vec3 n = Vec3::Zero();
            n[best_axis] = (best_hi != b.interior) ? 1.f : -1.f;
            const float lambert = std::max(0.f, n.dot((scene.light - p).normalized()));
            colour *= scene.ambient + (1.f - scene.ambient) * lambert;
          }
          for (const Billboard& bb : boards) {
            if (!bb.rect.Contains(u, v)) continue;
            const float denom = d.dot(bb.normal);
            if (denom > -1e-6f) continue;
            const float t_plane = (bb.foot - c).dot(bb.normal) / denom;
            if (t_plane <= 0.f || t_plane - bb.bulge / denom >= best_t + 0.3f) continue;
            const Vec3 q = c + t_plane * d - bb.foot;
            const Sprite& sp = *bb.sprite;
            const float across = q.dot(bb.right) / bb.width + 0.5f;
            const float scol = (bb.mirrored ? 1.f - across : across) * sp.bgr.cols;
            const float srow = (1.f - q.dot(bb.up) / bb.height) * sp.bgr.rows;
            const int ic = static_cast<int>(std::floor(scol)), ir = static_cast<int>(std::floor(srow));
            if (ic < 0 || ir < 0 || ic >= sp.bgr.cols || ir >= sp.bgr.rows) continue;
            if (sp.alpha.at<uchar>(ir, ic) <= 127) continue;
            const float x = (scol - sp.row_mid[ir]) / sp.row_half[ir];
            const float bulge = bb.bulge * std::sqrt(std::max(0.f, 1.f - x * x));
            const float t_hit = t_plane + bulge / denom;  // denom < 0: nearer than the plane
            if (t_hit >= best_t) continue;
            best_t = t_hit;
            id = static_cast<uint16_t>(bb.id);
            colour = Bilinear(sp.bgr, scol, srow) * (0.9f + 0.1f * std::sqrt(std::max(0.f, 1.f - x * x)));
            ir_level = 0.114f * colour[0] + 0.587f * colour[1] + 0.299f * colour[2];
          }
          rgb[u] = cv::Vec3b(cv::saturate_cast<uchar>(colour[0]), cv::saturate_cast<uchar>(colour[1]),
                             cv::saturate_cast<uchar>(colour[2]));
          dep[u] = std::isfinite(best_t) ? best_t : 0.f;
          ids[u] = id;
          if (irs != nullptr) irs[u] = cv::saturate_cast<uchar>(ir_level);
        }
      }
    }
  });
}

}  // namespace detslam::synth
