#include "core/hierarchy/hierarchy.h"

#include <algorithm>

namespace radiosity {
namespace {

// Parameter coordinates of the samples of each child, in the parent's space:
// (u, v) on the unit square for quads, barycentric (l1, l2) for triangles.
struct ChildSample {
  double a, b;
};

// Quad corners at (0,0) (1,0) (1,1) (0,1); children in the order of subdivide().
constexpr ChildSample kQuadChildSamples[4][5] = {
    {{0, 0}, {.5, 0}, {.5, .5}, {0, .5}, {.25, .25}},
    {{.5, 0}, {1, 0}, {1, .5}, {.5, .5}, {.75, .25}},
    {{.5, .5}, {1, .5}, {1, 1}, {.5, 1}, {.75, .75}},
    {{0, .5}, {.5, .5}, {.5, 1}, {0, 1}, {.25, .75}},
};

// Triangle corners at barycentric l1, l2 = (0,0) (1,0) (0,1); the fourth value is unused.
constexpr ChildSample kTriangleChildSamples[4][5] = {
    {{0, 0}, {.5, 0}, {0, .5}, {1.0 / 6, 1.0 / 6}, {}},
    {{.5, 0}, {1, 0}, {.5, .5}, {2.0 / 3, 1.0 / 6}, {}},
    {{0, .5}, {.5, .5}, {0, 1}, {1.0 / 6, 2.0 / 3}, {}},
    {{.5, .5}, {0, .5}, {.5, 0}, {1.0 / 3, 1.0 / 3}, {}},
};

// Weights of the parent's samples (corners, then centre) in its interpolant at (a, b).
std::array<double, kMaxSamples> interpolant_weights(int corner_count, double a, double b) {
  std::array<double, kMaxSamples> w{};
  if (corner_count == 4) {
    const double u = a, v = b;
    w[0] = (1 - u) * (1 - v);
    w[1] = u * (1 - v);
    w[2] = u * v;
    w[3] = (1 - u) * v;
    // Bubble: 1 at the centre, 0 on the edges, carries the centre's excess
    // over the bilinear average of the corners.
    const double bubble = 16 * u * (1 - u) * v * (1 - v);
    for (int k = 0; k < 4; ++k) w[k] -= 0.25 * bubble;
    w[4] = bubble;
  } else {
    const double l1 = a, l2 = b, l0 = 1 - a - b;
    w[0] = l0;
    w[1] = l1;
    w[2] = l2;
    const double bubble = 27 * l0 * l1 * l2;
    for (int k = 0; k < 3; ++k) w[k] -= bubble / 3;
    w[3] = bubble;
  }
  return w;
}

struct ChildWeightTable {
  // [triangle = 0 | quad = 1][child][child sample][parent sample]
  double w[2][4][kMaxSamples][kMaxSamples] = {};
  ChildWeightTable() {
    for (int c = 0; c < 4; ++c) {
      for (int s = 0; s < 5; ++s) {
        const auto& q = kQuadChildSamples[c][s];
        const auto wq = interpolant_weights(4, q.a, q.b);
        std::copy(wq.begin(), wq.end(), w[1][c][s]);
        if (s < 4) {
          const auto& t = kTriangleChildSamples[c][s];
          const auto wt = interpolant_weights(3, t.a, t.b);
          std::copy(wt.begin(), wt.end(), w[0][c][s]);
        }
      }
    }
  }
};

const ChildWeightTable& child_weights() {
  static const ChildWeightTable table;
  return table;
}

}  // namespace

Rgb Interpolant::at_child_sample(int corner_count, const std::array<Rgb, kMaxSamples>& values,
                                 int c, int s) {
  const double* w = child_weights().w[corner_count == 4 ? 1 : 0][c][s];
  glm::dvec3 sum(0.0);
  for (int k = 0; k <= corner_count; ++k) sum += w[k] * glm::dvec3(values[static_cast<size_t>(k)]);
  // The bubble can overshoot below zero where the centre is much darker than
  // the corners; gathered light is never negative.
  return glm::max(Rgb(sum), Rgb(0.0));
}

AverageWeights Interpolant::uniform_weights(int corner_count) {
  // Integrals over the element of the bubbles: 16 u(1-u) v(1-v) -> 4/9, and
  // 27 l0 l1 l2 -> 9/20 (of the area); the corners share the rest equally.
  const double bubble = corner_count == 4 ? 4.0 / 9.0 : 9.0 / 20.0;
  AverageWeights w{};
  for (int k = 0; k < corner_count; ++k) w[static_cast<size_t>(k)] = (1 - bubble) / corner_count;
  w[static_cast<size_t>(corner_count)] = bubble;
  return w;
}

AverageWeights Interpolant::quad_weights(const std::array<double, 4>& corner_density) {
  // The density J is bilinear in (u, v) through its corner values J_m, so
  // the integral of the interpolant times J is exact with the integrals of
  // products of the bilinear basis: 1/9 (same corner), 1/18 (corners along
  // an edge), 1/36 (opposite corners); and of the bubble times each basis
  // function, 1/9. Over the area (sum J_m / 4), with j_m = J_m over their
  // mean: corner k's weight sum_m M_km j_m less its share of the bubble's
  // bilinear part, 1/9; the centre's stays 4/9.
  const double mean =
      0.25 * (corner_density[0] + corner_density[1] + corner_density[2] + corner_density[3]);
  if (!(mean > 0.0)) return uniform_weights(4);
  AverageWeights w{};
  for (size_t k = 0; k < 4; ++k) {
    const double same = corner_density[k], opposite = corner_density[(k + 2) % 4];
    const double along = corner_density[(k + 1) % 4] + corner_density[(k + 3) % 4];
    w[k] = (same / 9.0 + along / 18.0 + opposite / 36.0) / mean - 1.0 / 9.0;
  }
  w[4] = 4.0 / 9.0;
  return w;
}

Rgb Interpolant::average(const AverageWeights& weights, int corner_count,
                         const std::array<Rgb, kMaxSamples>& values) {
  glm::dvec3 sum(0.0);
  for (int k = 0; k <= corner_count; ++k)
    sum += weights[static_cast<size_t>(k)] * glm::dvec3(values[static_cast<size_t>(k)]);
  return Rgb(sum);
}

namespace {

// A corner of a top-level element: patches of the same side of one input face
// (the triangles of an n-gon, the pieces of a face split by contact.h) share
// their coinciding corners, so their elements meet without cracks and their
// radiance is averaged there.
struct CornerKey {
  std::uint32_t face;
  std::uint8_t face_side;
  std::uint32_t corner_class;  // Patch::corner_class: which side of a discontinuity
  dvec3 position;
  bool operator==(const CornerKey& o) const {
    return face == o.face && face_side == o.face_side && corner_class == o.corner_class &&
           position == o.position;
  }
};

struct CornerHash {
  size_t operator()(const CornerKey& k) const {
    size_t h =
        std::hash<std::uint64_t>()((static_cast<std::uint64_t>(k.face) << 33) ^
                                   (static_cast<std::uint64_t>(k.corner_class) << 1) ^ k.face_side);
    for (int i = 0; i < 3; ++i) h = h * 1000003u ^ std::hash<double>()(k.position[i]);
    return h;
  }
};

}  // namespace

Hierarchy::Hierarchy(const Scene& scene) : scene_(&scene) {
  roots_.assign(2 * scene.patches.size(), kNone);
  std::unordered_map<CornerKey, std::uint32_t, CornerHash> shared;
  for (std::uint32_t p = 0; p < scene.patches.size(); ++p) {
    const Patch& patch = scene.patches[p];
    for (int side = 0; side < 2; ++side) {
      if (!patch.sides[static_cast<size_t>(side)].present) continue;
      Element e;
      e.patch = p;
      e.side = static_cast<std::uint8_t>(side);
      e.corner_count = patch.corner_count;
      e.area = patch.area;
      // Each side has its own vertices (its own radiance); the back side winds
      // the other way so its corners are counter-clockwise about its normal.
      const PatchSide& shown = patch.sides[static_cast<size_t>(side)];
      for (int k = 0; k < patch.corner_count; ++k) {
        const int source = side == 0 ? k : (patch.corner_count - k) % patch.corner_count;
        const dvec3 corner =
            patch.corners[static_cast<size_t>(source)] + dvec3(0.0);  // no -0.0 in the key
        const auto [it, made] =
            shared.try_emplace(CornerKey{shown.face, shown.face_side,
                                         patch.corner_class[static_cast<size_t>(source)], corner},
                               0u);
        if (made) it->second = add_vertex(corner);
        e.corner[static_cast<size_t>(k)] = it->second;
      }
      e.radiance = patch.sides[static_cast<size_t>(side)].emission;
      roots_[2 * p + static_cast<size_t>(side)] = static_cast<std::int32_t>(elements_.size());
      elements_.push_back(e);
    }
  }
}

int Hierarchy::corners(const Element& e, dvec3* out) const {
  for (int k = 0; k < e.corner_count; ++k) out[k] = vertices_[e.corner[static_cast<size_t>(k)]];
  return e.corner_count;
}

AverageWeights Hierarchy::average_weights(const Element& e) const {
  if (e.corner_count != 4) return Interpolant::uniform_weights(e.corner_count);
  dvec3 c[4];
  corners(e, c);
  // The bilinear map's area density at each corner: the cross product of the
  // two edges leaving it, measured along the quad's normal (its diagonals').
  const dvec3 up = glm::cross(c[2] - c[0], c[3] - c[1]);
  std::array<double, 4> density{};
  for (size_t k = 0; k < 4; ++k) {
    const dvec3 next = c[(k + 1) % 4] - c[k], previous = c[k] - c[(k + 3) % 4];
    density[k] = glm::dot(glm::cross(previous, next), up);
  }
  return Interpolant::quad_weights(density);
}

dvec3 Hierarchy::centre(const Element& e) const {
  dvec3 sum(0.0);
  for (int k = 0; k < e.corner_count; ++k) sum += vertices_[e.corner[static_cast<size_t>(k)]];
  return sum / static_cast<double>(e.corner_count);
}

double Hierarchy::diameter(const Element& e) const {
  double d = 0.0;
  for (int i = 0; i < e.corner_count; ++i) {
    for (int j = i + 1; j < e.corner_count; ++j) {
      d = std::max(d, glm::length(vertices_[e.corner[static_cast<size_t>(i)]] -
                                  vertices_[e.corner[static_cast<size_t>(j)]]));
    }
  }
  return d;
}

namespace {

// How far a sample at `v` keeps from the patch's inset edges (Patch::edge_inset).
double inset_at(const Patch& p, const dvec3& v) {
  double inset = 0.0;
  for (int j = 0; j < p.corner_count; ++j) {
    const double wanted = static_cast<double>(p.edge_inset[static_cast<size_t>(j)]);
    if (!(wanted > inset)) continue;
    const dvec3& a = p.corners[static_cast<size_t>(j)];
    const dvec3 ab = p.corners[static_cast<size_t>((j + 1) % p.corner_count)] - a;
    const double t = std::clamp(glm::dot(v - a, ab) / glm::dot(ab, ab), 0.0, 1.0);
    if (glm::length(v - (a + t * ab)) <= 1e-9 * glm::length(ab)) inset = wanted;
  }
  return inset;
}

}  // namespace

bool Hierarchy::samples_inset(const Element& e) const {
  if (!has_insets(e)) return false;
  const Patch& patch = patch_of(e);
  for (int k = 0; k < e.corner_count; ++k)
    if (inset_at(patch, vertices_[e.corner[static_cast<size_t>(k)]]) > 0.0) return true;
  return false;
}

int Hierarchy::samples(const Element& e, dvec3* out) const {
  const dvec3 c = centre(e);
  const Patch& patch = patch_of(e);
  const bool insets = has_insets(e);
  for (int k = 0; k < e.corner_count; ++k) {
    const dvec3& v = vertices_[e.corner[static_cast<size_t>(k)]];
    double move = 1e-6;
    if (insets) {
      const double to_centre = glm::length(c - v);
      move = std::max(move, std::min(0.25, inset_at(patch, v) / to_centre));
    }
    out[k] = v + move * (c - v);
  }
  out[e.corner_count] = c;
  return e.corner_count + 1;
}

std::uint32_t Hierarchy::add_vertex(const dvec3& p) {
  vertices_.push_back(p);
  return static_cast<std::uint32_t>(vertices_.size() - 1);
}

std::uint64_t Hierarchy::edge_key(std::uint32_t a, std::uint32_t b) {
  if (a > b) std::swap(a, b);
  return (static_cast<std::uint64_t>(a) << 32) | b;
}

std::uint32_t Hierarchy::midpoint_or_add(std::uint32_t a, std::uint32_t b) {
  const auto [it, inserted] = midpoints_.try_emplace(edge_key(a, b), 0u);
  if (inserted) it->second = add_vertex(0.5 * (vertices_[a] + vertices_[b]));
  return it->second;
}

std::int32_t Hierarchy::midpoint(std::uint32_t a, std::uint32_t b) const {
  const auto it = midpoints_.find(edge_key(a, b));
  return it == midpoints_.end() ? kNone : static_cast<std::int32_t>(it->second);
}

std::int32_t Hierarchy::subdivide(std::int32_t index) {
  if (element(index).first_child != kNone) return element(index).first_child;
  const Element parent = element(index);
  const auto& c = parent.corner;
  std::array<std::array<std::uint32_t, 4>, 4> children{};
  if (parent.corner_count == 4) {
    const std::uint32_t m01 = midpoint_or_add(c[0], c[1]), m12 = midpoint_or_add(c[1], c[2]);
    const std::uint32_t m23 = midpoint_or_add(c[2], c[3]), m30 = midpoint_or_add(c[3], c[0]);
    const std::uint32_t mid = add_vertex(centre(parent));
    children = {{{c[0], m01, mid, m30},
                 {m01, c[1], m12, mid},
                 {mid, m12, c[2], m23},
                 {m30, mid, m23, c[3]}}};
  } else {
    const std::uint32_t m01 = midpoint_or_add(c[0], c[1]), m12 = midpoint_or_add(c[1], c[2]);
    const std::uint32_t m20 = midpoint_or_add(c[2], c[0]);
    children = {
        {{c[0], m01, m20, 0}, {m01, c[1], m12, 0}, {m20, m12, c[2], 0}, {m12, m20, m01, 0}}};
  }
  const auto first = static_cast<std::int32_t>(elements_.size());
  for (int k = 0; k < 4; ++k) {
    // A triangle's four children are congruent; a quad's are the parts of its
    // bilinear map, equal only in a parallelogram (a floor piece cut around a
    // rotated box, counted as quarters, took or gave its wide end's light:
    // 3.6 % of a spot's direct light).
    const auto& corner = children[static_cast<size_t>(k)];
    const double area =
        parent.corner_count == 4
            ? 0.5 * glm::length(glm::cross(vertices_[corner[2]] - vertices_[corner[0]],
                                           vertices_[corner[3]] - vertices_[corner[1]]))
            : parent.area / 4;
    Element child;
    child.corner = corner;
    child.parent = index;
    child.patch = parent.patch;
    child.side = parent.side;
    child.corner_count = parent.corner_count;
    child.has_links = parent.has_links;
    child.area = area;
    child.radiance = parent.radiance;
    elements_.push_back(child);
  }
  element(index).first_child = first;
  return first;
}

std::size_t Hierarchy::memory_bytes() const {
  return elements_.capacity() * sizeof(Element) + vertices_.capacity() * sizeof(dvec3) +
         midpoints_.size() * (sizeof(std::uint64_t) + sizeof(std::uint32_t) + 2 * sizeof(void*)) +
         roots_.capacity() * sizeof(std::int32_t);
}

}  // namespace radiosity
