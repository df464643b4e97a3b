// The rooms of the place-recognition presets: a large office for `loop_long` and the two-part
// room of `lookalike` (see scene.h).
#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <vector>

#include "detslam/core/check.h"
#include "detslam/core/rng.h"
#include "detslam/synth/scene.h"
#include "detslam/synth/scene_builder.h"

namespace detslam::synth {
namespace {

using V = Eigen::Vector3f;

// A wall of a room seen from inside: the plane `axis` = `at` (axis 0 or 1), the room on the side
// `inward` (+1: larger coordinates).
struct Wall {
  int axis = 0;
  float at = 0.f;
  float inward = 1.f;
};

// A box standing against `wall`: [s0, s1] along the wall, `depth` into the room, z in [z0, z1];
// its face towards the room uses `front`.
void WallBox(SceneBuilder& b, const Wall& wall, float s0, float s1, float depth, float z0, float z1,
             SurfaceKind sides, SurfaceKind top, SurfaceKind front) {
  const int along = 1 - wall.axis;
  V lo, hi;
  lo[along] = s0;
  hi[along] = s1;
  lo[2] = z0;
  hi[2] = z1;
  lo[wall.axis] = wall.inward > 0 ? wall.at : wall.at - depth;
  hi[wall.axis] = wall.inward > 0 ? wall.at + depth : wall.at;
  b.Box(lo, hi, sides, top, FaceIndex(wall.axis, wall.inward > 0), front);
}

// Lines `wall` between s0 and s1 with a seeded mix of bookshelves, cabinets and cardboard boxes
// (often with a poster above), doors and posters, with gaps of bare wall between them.
void FurnishWall(SceneBuilder& b, Rng& rng, const Wall& wall, float s0, float s1) {
  const auto u = [&](double lo, double hi) { return static_cast<float>(rng.Uniform(lo, hi)); };
  float s = s0 + u(0.05, 0.4);
  while (s < s1 - 0.4f) {
    const float width = std::min(u(0.5, 1.4), s1 - s);
    const double kind = rng.Uniform();
    if (kind < 0.22) {
      WallBox(b, wall, s, s + width, 0.38f, 0.f, u(1.5, 2.0), SurfaceKind::kWood,
              SurfaceKind::kWood, SurfaceKind::kBooks);
    } else if (kind < 0.62) {
      const bool cabinet = rng.Uniform() < 0.5;
      const float top = u(0.45, 1.1);
      const SurfaceKind material = cabinet ? SurfaceKind::kMetal : SurfaceKind::kCardboard;
      WallBox(b, wall, s, s + width, cabinet ? 0.5f : u(0.35, 0.6), 0.f, top, material,
              cabinet ? SurfaceKind::kWood : SurfaceKind::kCardboard, material);
      if (rng.Uniform() < 0.7) {
        const float z0 = top + u(0.15, 0.35);
        WallBox(b, wall, s + u(0.0, 0.15), s + width - u(0.0, 0.15), 0.03f, z0,
                std::min(2.4f, z0 + u(0.5, 0.9)), SurfaceKind::kWall, SurfaceKind::kWall,
                SurfaceKind::kPoster);
      }
    } else if (kind < 0.75) {
      WallBox(b, wall, s, s + std::min(width, 0.95f), 0.05f, 0.f, 2.1f, SurfaceKind::kWood,
              SurfaceKind::kWood, SurfaceKind::kWood);
    } else {
      const float z0 = u(0.9, 1.3);
      WallBox(b, wall, s, s + width, 0.03f, z0, z0 + u(0.5, 1.0), SurfaceKind::kWall,
              SurfaceKind::kWall, SurfaceKind::kPoster);
    }
    s += width + u(0.1, 0.6);
  }
}

// --- lookalike ---------------------------------------------------------------------------------

constexpr float kFarWall = 2.6f;    // y of the far wall the camera faces
constexpr int kColumns = 7;         // cells per row in each part
constexpr float kCellWidth = 0.7f;  // metres
constexpr float kPartWidth = kColumns * kCellWidth;
constexpr int kRows = 4;
// Rows of cells: 0 stands on the floor, 1-3 hang on the wall (z ranges, metres).
constexpr float kRowZ[kRows][2] = {{0.f, 0.9f}, {1.0f, 1.4f}, {1.45f, 1.85f}, {1.9f, 2.3f}};

// One furnishing: its look (the same in both parts) and its placement in each part.
struct Item {
  SurfaceKind sides{}, top{}, front{};        // textures' kinds
  float depth = 0.f;                          // how far it stands out of the wall (base)
  std::array<V, 2> lo{V::Zero(), V::Zero()};  // box in part 0 (first) and part 1 (second)
  std::array<V, 2> hi{V::Zero(), V::Zero()};
};

Item MakeItem(SurfaceKind sides, SurfaceKind top, SurfaceKind front, float depth) {
  Item it;
  it.sides = sides;
  it.top = top;
  it.front = front;
  it.depth = depth;
  return it;
}

// Places `item` in cell (row, col) of part `part` (x0: the left edge of the row's cells) with a
// seeded size (at least 6 cm wider or narrower in the second part); its top left corner (the front
// texture's origin) stays within 4 cm of the cell's, so that items move between the parts by their
// cells' step, give or take 8 cm. A floor item keeps its height (the top is its texture's origin)
// and changes width and depth.
void Place(Item& item, int part, float x0, int row, int col, Rng& rng) {
  const auto u = [&](double lo, double hi) { return static_cast<float>(rng.Uniform(lo, hi)); };
  const float* zr = kRowZ[row];
  float w = u(0.42, 0.62);
  if (part == 1) {  // at least 6 cm wider or narrower than in the first part
    const float first_w = item.hi[0].x() - item.lo[0].x();
    w = first_w > 0.52f ? first_w - u(0.06, 0.15) : first_w + u(0.06, 0.1);
  }
  float h = row == 0 ? u(0.5, zr[1] - zr[0]) : u(0.28, zr[1] - zr[0] - 0.04);
  if (row == 0 && part == 1) h = item.hi[0].z();
  const float d = item.depth * u(0.7, 1.0);
  const float x = x0 + col * kCellWidth + u(0.02, 0.06);
  const float z = row == 0 ? 0.f : zr[1] - u(0.0, 0.04) - h;
  item.lo[part] = V(x, kFarWall - d, z);
  item.hi[part] = V(x + w, kFarWall, z + h);
}

// Where the front texture's origin is (FaceTexel of the y-lo face: column from lo.x, row from
// hi.z): an item's texture moves between the parts by the difference of its anchors.
V FrontAnchor(const Item& item, int part) {
  return V(item.lo[part].x(), item.lo[part].y(), item.hi[part].z());
}

// Smallest difference between two items' moves from the first part to the second: a rigid motion
// that carries one item's texture onto its twin carries no other item's texture onto its twin
// within this distance.
float MinMoveDifference(const std::vector<Item>& items) {
  float best = 1e9f;
  for (size_t i = 0; i < items.size(); ++i) {
    const V ti = FrontAnchor(items[i], 1) - FrontAnchor(items[i], 0);
    for (size_t j = i + 1; j < items.size(); ++j) {
      const V tj = FrontAnchor(items[j], 1) - FrontAnchor(items[j], 0);
      best = std::min(best, (ti - tj).norm());
    }
  }
  return best;
}

// A permutation of n cells (row-major numbers) that moves every cell by a different number of
// cells, hence by a different (rows, columns) step: k -> (a k + s) mod n with a and a - 1 coprime
// to n, so the move (a - 1) k + s (mod n) differs for every k.
std::vector<int> DistinctMovePermutation(int n, Rng& rng) {
  std::vector<int> multipliers;
  for (int a = 2; a < n; ++a) {
    if (std::gcd(a, n) == 1 && std::gcd(a - 1, n) == 1) multipliers.push_back(a);
  }
  DETSLAM_CHECK_MSG(!multipliers.empty(), "no distinct-move permutation of " << n << " cells");
  const int a = multipliers[rng.UniformInt(0, static_cast<int>(multipliers.size()) - 1)];
  const int s = rng.UniformInt(0, n - 1);
  std::vector<int> perm(n);
  for (int k = 0; k < n; ++k) perm[k] = (a * k + s) % n;
  return perm;
}

// The items of the cells, row-major: cabinets, cardboard boxes and low shelves on the floor;
// posters, screens and wall shelves above.
std::vector<Item> LookalikeItems(Rng& rng) {
  std::vector<Item> items;
  for (int row = 0; row < kRows; ++row) {
    for (int col = 0; col < kColumns; ++col) {
      const double kind = rng.Uniform();
      if (row == 0) {
        if (kind < 0.35) {
          items.push_back(
              MakeItem(SurfaceKind::kMetal, SurfaceKind::kWood, SurfaceKind::kMetal, 0.5f));
        } else if (kind < 0.7) {
          items.push_back(MakeItem(SurfaceKind::kCardboard, SurfaceKind::kCardboard,
                                   SurfaceKind::kCardboard, 0.5f));
        } else {
          items.push_back(
              MakeItem(SurfaceKind::kWood, SurfaceKind::kWood, SurfaceKind::kBooks, 0.35f));
        }
      } else if (kind < 0.5) {
        items.push_back(
            MakeItem(SurfaceKind::kWall, SurfaceKind::kWall, SurfaceKind::kPoster, 0.03f));
      } else if (kind < 0.7) {
        items.push_back(
            MakeItem(SurfaceKind::kMetal, SurfaceKind::kMetal, SurfaceKind::kScreen, 0.06f));
      } else {
        items.push_back(
            MakeItem(SurfaceKind::kWood, SurfaceKind::kWood, SurfaceKind::kBooks, 0.25f));
      }
    }
  }
  return items;
}

}  // namespace

Scene BuildLargeOfficeScene(uint64_t seed, const TextureStyle& style) {
  SceneBuilder b(seed ^ 0x1A26EULL, style);
  Rng layout(seed ^ 0x1A40FULL);
  const float hx = 6.3f, hy = 4.2f;
  b.Box(V(-hx, -hy, 0.f), V(hx, hy, 2.8f), SurfaceKind::kWall, SurfaceKind::kCeiling,
        FaceIndex(2, false), SurfaceKind::kFloor, true);
  // The walls in the order the loop passes them; corners (0.75 m) stay free.
  const Wall walls[4] = {{1, -hy, 1.f}, {0, hx, -1.f}, {1, hy, -1.f}, {0, -hx, 1.f}};
  for (const Wall& wall : walls) {
    const float half = wall.axis == 1 ? hx : hy;
    FurnishWall(b, layout, wall, -half + 0.75f, half - 0.75f);
  }
  if (style.windows) {
    // High windows above the furnishings along both long walls (added last, so the other
    // surfaces keep their textures).
    const SurfaceKind W = SurfaceKind::kWall, G = SurfaceKind::kWindow;
    for (const float s : {-4.5f, -1.0f, 2.5f}) {
      b.Box(V(s, -hy, 2.15f), V(s + 2.0f, -hy + 0.01f, 2.7f), W, W, FaceIndex(1, true), G);
      b.Box(V(s, hy - 0.01f, 2.15f), V(s + 2.0f, hy, 2.7f), W, W, FaceIndex(1, false), G);
    }
  }
  return b.Take();
}

LookalikeScene BuildLookalikeScene(uint64_t seed, const TextureStyle& style) {
  SceneBuilder b(seed ^ 0x100CA1EULL, style);
  Rng layout(seed ^ 0x1A7E5ULL);
  // A far, high light: nearly the same shading everywhere along the far wall, so that an item
  // looks the same in both parts.
  b.scene().light = Eigen::Vector3f(0.f, -30.f, 12.f);
  // Plain walls: what the camera sees is mostly the furnishings, which both parts share.
  b.Box(V(-6.4f, -2.4f, 0.f), V(6.4f, kFarWall, 2.8f), SurfaceKind::kPlainWall,
        SurfaceKind::kCeiling, FaceIndex(2, false), SurfaceKind::kFloor, true);
  // The neutral stretch between the parts: a door and a small notice board, textures of their own.
  b.Box(V(-0.45f, kFarWall - 0.05f, 0.f), V(0.45f, kFarWall, 2.1f), SurfaceKind::kWood,
        SurfaceKind::kWood, FaceIndex(1, false), SurfaceKind::kWood);
  b.Box(V(-0.35f, kFarWall - 0.08f, 2.15f), V(0.3f, kFarWall - 0.05f, 2.55f), SurfaceKind::kWall,
        SurfaceKind::kWall, FaceIndex(1, false), SurfaceKind::kPoster);

  // The first part fills its cells in order. The second part permutes the wall items among the
  // wall cells so that every item moves by a different step of cells, and the floor items among
  // the floor cells likewise, on a floor grid shifted by half a cell so that no floor item moves
  // like a wall item. Then no two items' moves are within 0.25 m: no rigid motion carries two
  // items onto their twins.
  const float first_x0 = LookalikeScene::kFirstPartMaxX - kPartWidth;
  const float second_x0 = LookalikeScene::kSecondPartMinX;
  std::vector<Item> items = LookalikeItems(layout);
  for (size_t i = 0; i < items.size(); ++i) {
    Place(items[i], 0, first_x0, static_cast<int>(i) / kColumns, static_cast<int>(i) % kColumns,
          layout);
  }
  const std::vector<int> floor = DistinctMovePermutation(kColumns, layout);
  const std::vector<int> wall = DistinctMovePermutation((kRows - 1) * kColumns, layout);
  for (int i = 0; i < static_cast<int>(items.size()); ++i) {
    const int cell = i < kColumns ? floor[i] : kColumns + wall[i - kColumns];
    const float x0 = cell < kColumns ? second_x0 + 0.5f * kCellWidth : second_x0;
    Place(items[i], 1, x0, cell / kColumns, cell % kColumns, layout);
  }
  DETSLAM_CHECK_MSG(MinMoveDifference(items) > 0.25f, "lookalike layout: two items move alike");

  LookalikeScene out;
  for (const Item& it : items) {
    const V extent = (it.hi[0] - it.lo[0]).cwiseMax(it.hi[1] - it.lo[1]);
    const std::array<int, 6> textures =
        b.Textures(extent, it.sides, it.top, FaceIndex(1, false), it.front);
    const int first = b.AddBox(it.lo[0], it.hi[0], textures);
    const int second = b.AddBox(it.lo[1], it.hi[1], textures);
    out.twins.emplace_back(first, second);
  }
  out.scene = b.Take();
  return out;
}

}  // namespace detslam::synth
