#include "core/scene/contact.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <vector>

#include "core/geometry/polygon.h"
#include "core/geometry/triangle.h"
#include "core/visibility/scene_bvh.h"

namespace radiosity {
namespace {

constexpr double kParallelCosine = 0.99619469809174553;  // cos 5 degrees
constexpr double kCoverGap = 0.1;                        // of the smaller face's diameter
constexpr double kFootGap = 0.01;                        // of the touching face's diameter
constexpr double kCoincident = 1e-5;                     // of the larger face's diameter
constexpr double kCoincidentScene = 1e-6;                // of the scene's diameter
constexpr double kThinnest = 1e-4;                       // of the cut face's diameter
// Pieces narrower than this share of the cut face's diameter are not cut off
// unless a light makes the cut: the strip under a cabinet's 3 cm side panel
// or the 1 cm between a cabinet and the wall behind it, cut across a 5 m
// floor, became slivers that refined into thousands of elements (full_office:
// 3 times the floor's elements), for a discontinuity a few centimetres from
// an element's edge.
constexpr double kNarrowest = 0.01;
// A face smaller than this share of the cut face's diameter (a chair leg on a
// floor, a table leg under its top) is not cut around unless it emits: it
// covers at most 0.25 % of the face, so what could leak under it is
// negligible, while its cuts, run across the pieces they cross, multiplied the
// floor's pieces (full_office: 2.2 times the patches at 0 %), and every corner
// on them sits a millionth from a face that meets it, where the oracles see a
// near-singular gradient and refine (at 2 %: 1.4 times the links of 5 %).
constexpr double kSmallest = 0.05;

// A corner of a piece: in the plane of the patch being cut, and in space
// (kept exactly for the patch's own corners, interpolated along the edge it
// splits for the others, so that pieces sharing a corner share it exactly).
struct Vertex {
  dvec2 p;
  dvec3 x;
};
using Polygon2 = std::vector<Vertex>;  // convex, counter-clockwise in the frame

struct Frame {
  dvec3 origin{0.0}, u{0.0}, v{0.0}, n{0.0};
  dvec2 to2(const dvec3& x) const {
    const dvec3 d = x - origin;
    return {glm::dot(d, u), glm::dot(d, v)};
  }
};

Frame frame_of(const Patch& p) {
  Frame f;
  f.origin = p.corners[0];
  f.n = p.normal;
  f.u = glm::normalize(p.corners[1] - p.corners[0]);
  f.v = glm::cross(f.n, f.u);
  return f;
}

double diameter_of(const Patch& p) {
  double d = 0.0;
  for (int i = 0; i < p.corner_count; ++i)
    for (int j = i + 1; j < p.corner_count; ++j)
      d = std::max(
          d, glm::length(p.corners[static_cast<size_t>(i)] - p.corners[static_cast<size_t>(j)]));
  return d;
}

std::vector<dvec2> points_of(const Polygon2& piece) {
  std::vector<dvec2> out;
  for (const Vertex& v : piece) out.push_back(v.p);
  return out;
}

dvec2 centroid_of(const std::vector<dvec2>& polygon) {
  dvec2 c(0.0);
  double area = 0.0;
  for (size_t i = 0; i < polygon.size(); ++i) {
    const dvec2& a = polygon[i];
    const dvec2& b = polygon[(i + 1) % polygon.size()];
    const double w = cross2(a, b);
    c += w * (a + b);
    area += w;
  }
  return std::abs(area) > 0.0 ? c / (3.0 * area) : polygon[0];
}

bool inside(const std::vector<dvec2>& ccw, const dvec2& q, double tolerance) {
  for (size_t i = 0; i < ccw.size(); ++i) {
    const dvec2 e = ccw[(i + 1) % ccw.size()] - ccw[i];
    if (cross2(e, q - ccw[i]) < -tolerance * glm::length(e)) return false;
  }
  return true;
}

// Convex counter-clockwise polygons that share more than a strip `tolerance`
// wide: no edge of either has the other wholly on or past its line.
bool overlap(const std::vector<dvec2>& a, const std::vector<dvec2>& b, double tolerance) {
  const auto separates = [tolerance](const std::vector<dvec2>& edges,
                                     const std::vector<dvec2>& other) {
    for (size_t i = 0; i < edges.size(); ++i) {
      const dvec2 e = edges[(i + 1) % edges.size()] - edges[i];
      bool all_out = true;
      for (const dvec2& q : other) all_out &= cross2(e, q - edges[i]) <= tolerance * glm::length(e);
      if (all_out) return true;
    }
    return false;
  };
  return !separates(a, b) && !separates(b, a);
}

struct Segment {
  dvec2 a{0.0}, b{0.0};
};

// Length of the part of the line through `s`, between its parameters t0 and
// t1 (0 and 1 are its ends), inside the convex piece.
double length_inside(const Polygon2& piece, const Segment& s, double t0 = 0.0, double t1 = 1.0) {
  const dvec2 d = s.b - s.a;
  for (size_t i = 0; i < piece.size(); ++i) {
    const dvec2& p = piece[i].p;
    const dvec2 e = piece[(i + 1) % piece.size()].p - p;
    const double num = cross2(e, s.a - p), den = cross2(e, d);  // inside: num + t den >= 0
    if (std::abs(den) <= 1e-15 * glm::length(e) * glm::length(d)) {
      if (num < 0.0) return 0.0;
      continue;
    }
    const double t = -num / den;
    if (den > 0.0)
      t0 = std::max(t0, t);
    else
      t1 = std::min(t1, t);
    if (t0 >= t1) return 0.0;
  }
  return (t1 - t0) * glm::length(d);
}

// Splits a convex piece along the line of `s`. False (no split) when either
// side would be thinner than `thinnest` across the line.
bool split(const Polygon2& piece, const Segment& s, double thinnest, Polygon2& left,
           Polygon2& right) {
  const dvec2 d = glm::normalize(s.b - s.a);
  const double on_line = 1e-3 * thinnest;
  std::vector<double> distance(piece.size());
  double most_left = 0.0, most_right = 0.0;
  for (size_t i = 0; i < piece.size(); ++i) {
    distance[i] = cross2(d, piece[i].p - s.a);
    most_left = std::max(most_left, distance[i]);
    most_right = std::max(most_right, -distance[i]);
  }
  if (most_left < thinnest || most_right < thinnest) return false;
  left.clear();
  right.clear();
  for (size_t i = 0; i < piece.size(); ++i) {
    const size_t j = (i + 1) % piece.size();
    const double di = distance[i], dj = distance[j];
    if (di >= -on_line) left.push_back(piece[i]);
    if (di <= on_line) right.push_back(piece[i]);
    if ((di > on_line && dj < -on_line) || (di < -on_line && dj > on_line)) {
      const double t = di / (di - dj);
      const Vertex v{piece[i].p + t * (piece[j].p - piece[i].p),
                     piece[i].x + t * (piece[j].x - piece[i].x)};
      left.push_back(v);
      right.push_back(v);
    }
  }
  return left.size() >= 3 && right.size() >= 3;
}

// A line to cut along, and how narrow a piece it may leave.
struct Cut {
  Segment segment;
  double narrowest;
};

// The pieces a patch is cut into, each with its bounding box, so that a cut
// only looks at the pieces its segment can pass through.
class Pieces {
 public:
  explicit Pieces(const Polygon2& whole) { add(whole); }
  std::vector<Polygon2> take() { return std::move(polygons_); }

  // Calls visit(index) for every piece whose box meets the segment's.
  template <typename Visit>
  void near(const Segment& s, const Visit& visit) const {
    const dvec2 lo = glm::min(s.a, s.b), hi = glm::max(s.a, s.b);
    for (size_t i = 0; i < polygons_.size(); ++i)
      if (lo_[i].x <= hi.x && hi_[i].x >= lo.x && lo_[i].y <= hi.y && hi_[i].y >= lo.y) visit(i);
  }
  // Splits every piece the cut passes through along it.
  void cut(const Cut& cut, double thinnest) {
    std::vector<size_t> crossed;
    near(cut.segment, [&](size_t i) {
      if (length_inside(polygons_[i], cut.segment) > thinnest) crossed.push_back(i);
    });
    Polygon2 left, right;
    for (size_t i : crossed) {
      if (!split(polygons_[i], cut.segment, cut.narrowest, left, right)) continue;
      replace(i, left);
      add(right);
    }
  }
  // How far the cut runs past its own ends through the pieces it crosses.
  double past_ends(const Cut& cut, double thinnest) const {
    double past = 0.0;
    near(cut.segment, [&](size_t i) {
      const double inside = length_inside(polygons_[i], cut.segment);
      if (inside > thinnest) past += length_inside(polygons_[i], cut.segment, -1e9, 1e9) - inside;
    });
    return past;
  }

 private:
  void add(const Polygon2& polygon) {
    polygons_.emplace_back();
    lo_.emplace_back();
    hi_.emplace_back();
    replace(polygons_.size() - 1, polygon);
  }
  void replace(size_t i, const Polygon2& polygon) {
    polygons_[i] = polygon;
    lo_[i] = dvec2(std::numeric_limits<double>::infinity());
    hi_[i] = -lo_[i];
    for (const Vertex& v : polygons_[i]) {
      lo_[i] = glm::min(lo_[i], v.p);
      hi_[i] = glm::max(hi_[i], v.p);
    }
  }
  std::vector<Polygon2> polygons_;
  std::vector<dvec2> lo_, hi_;
};

// Cuts the convex piece along every segment. A cut runs across the whole
// piece it passes through, so that pieces stay convex; the order then decides
// how far cuts run past their ends: the cut that runs least past its ends goes
// first (greedy), so that a box's outline on a floor crosses the floor twice,
// not four times, and the outline of a cabinet against a wall not at all.
// Choosing among all cuts each time costs the cube of their number (a floor
// under a furnished house has thousands), so the choice is made within runs
// of kGreedyRun cuts in their order, which keeps the cuts of one covering face
// together.
constexpr size_t kGreedyRun = 24;

std::vector<Polygon2> cut_along(const Polygon2& whole, std::vector<Cut> cuts, double thinnest) {
  Pieces pieces(whole);
  for (size_t begin = 0; begin < cuts.size(); begin += kGreedyRun) {
    std::vector<Cut> run(
        cuts.begin() + static_cast<std::ptrdiff_t>(begin),
        cuts.begin() + static_cast<std::ptrdiff_t>(std::min(cuts.size(), begin + kGreedyRun)));
    while (!run.empty()) {
      size_t best = 0;
      double least = std::numeric_limits<double>::infinity();
      for (size_t k = 0; k < run.size(); ++k) {
        const double past = pieces.past_ends(run[k], thinnest);
        if (past < least) least = past, best = k;
      }
      pieces.cut(run[best], thinnest);
      run.erase(run.begin() + static_cast<std::ptrdiff_t>(best));
    }
  }
  return pieces.take();
}

// What of patch Q touches patch P: cut segments in P's frame, and, where Q
// lies in P's plane, Q's outline there (for merging coinciding pieces).
struct Contact {
  std::vector<Segment> cuts;
  std::vector<dvec2> cover_outline;  // counter-clockwise; empty if Q does not cover P
  double gap = 0.0;                  // of a cover: the farthest of its corners from P's plane
  bool coincident = false;           // a cover lying in P's plane
  bool meets = false;                // cuts[0] is where Q meets P's plane
  bool crosses = false;              // Q passes through P's plane there (not only rests on it)
};

bool emits(const Patch& q) {
  return luminance(q.sides[0].emission) > 0.0 || luminance(q.sides[1].emission) > 0.0;
}

// `outline_p`: P's outline, in its frame (counter-clockwise).
Contact contact_of(const Frame& f, const std::vector<dvec2>& outline_p, double dp, const Patch& q,
                   double dq, double scene_diameter) {
  Contact out;
  double s[4];
  double nearest = std::numeric_limits<double>::infinity(), farthest = 0.0, lo = 0.0, hi = 0.0;
  for (int i = 0; i < q.corner_count; ++i) {
    s[i] = glm::dot(f.n, q.corners[static_cast<size_t>(i)] - f.origin);
    nearest = std::min(nearest, std::abs(s[i]));
    farthest = std::max(farthest, std::abs(s[i]));
    lo = std::min(lo, s[i]);
    hi = std::max(hi, s[i]);
  }
  const double touch = std::max(kCoincident * std::max(dp, dq), kCoincidentScene * scene_diameter);
  if (std::abs(glm::dot(f.n, q.normal)) >= kParallelCosine) {
    if (farthest > kCoverGap * std::min(dp, dq)) return out;
    if (dq < kSmallest * dp && !emits(q)) return out;
    std::vector<dvec2> outline;
    for (int i = 0; i < q.corner_count; ++i)
      outline.push_back(f.to2(q.corners[static_cast<size_t>(i)]));
    if (signed_area(outline) < 0.0) std::reverse(outline.begin(), outline.end());
    // A neighbour that only borders P (the next face of a smooth mesh, bent
    // by a degree or two) covers nothing: no discontinuity, and no inset
    // samples along the edge they share (which cost Suzanne's faces the exact
    // 3 x 3 grid of every occluded link and their shared corners).
    if (!overlap(outline_p, outline, kThinnest * dp)) return out;
    for (size_t i = 0; i < outline.size(); ++i)
      out.cuts.push_back({outline[i], outline[(i + 1) % outline.size()]});
    out.coincident = farthest <= touch;
    out.gap = farthest;
    out.cover_outline = std::move(outline);
    return out;
  }
  // Where Q meets P's plane: the segment it crosses it along, or the edge
  // that rests on it.
  std::vector<dvec3> points;
  out.crosses = lo < -touch && hi > touch;
  if (out.crosses) {
    for (int i = 0; i < q.corner_count; ++i) {
      const int j = (i + 1) % q.corner_count;
      const dvec3& a = q.corners[static_cast<size_t>(i)];
      const dvec3& b = q.corners[static_cast<size_t>(j)];
      if (std::abs(s[i]) <= touch)
        points.push_back(a);
      else if ((s[i] > touch && s[j] < -touch) || (s[i] < -touch && s[j] > touch))
        points.push_back(a + (s[i] / (s[i] - s[j])) * (b - a));
    }
  } else {
    const double foot = std::max(touch, kFootGap * dq);
    if (nearest > foot) return out;
    for (int i = 0; i < q.corner_count; ++i)
      if (std::abs(s[i]) <= foot) points.push_back(q.corners[static_cast<size_t>(i)]);
  }
  if (points.size() < 2) return out;
  size_t a = 0, b = 1;
  double best = -1.0;
  for (size_t i = 0; i < points.size(); ++i)
    for (size_t j = i + 1; j < points.size(); ++j) {
      const double d = glm::length(points[i] - points[j]);
      if (d > best) best = d, a = i, b = j;
    }
  if (best < kSmallest * dp && !emits(q)) return out;
  out.cuts.push_back({f.to2(points[a]), f.to2(points[b])});
  out.meets = true;
  return out;
}

// A piece of a patch as it is cut, and what becomes of it.
struct Piece {
  Polygon2 polygon;
  std::array<PatchSide, 2> sides{};
  std::vector<std::uint32_t> coincides_with;  // patches whose outline it lies in, in its plane
  std::int64_t merged_into = -1;              // index in the flat piece list
  dvec3 centre{0.0};
  double area = 0.0;
  std::vector<std::uint32_t> corner_class;  // per polygon corner (Patch::corner_class)
  std::vector<float> edge_inset;            // per polygon edge (Patch::edge_inset)
};

// What in P's plane makes the radiance discontinuous: the outlines of covers
// (with their gap, 0 where they touch) and the segments where faces meet it.
struct Features {
  struct Cover {
    std::vector<dvec2> outline;
    double gap;
  };
  struct Meeting {
    Segment segment;
    bool crosses;  // the other face passes through this one there
  };
  std::vector<Cover> covers;
  std::vector<Meeting> meetings;
};

double distance_to_segment(const dvec2& p, const Segment& s) {
  const dvec2 d = s.b - s.a;
  const double t = std::clamp(glm::dot(p - s.a, d) / glm::dot(d, d), 0.0, 1.0);
  return glm::length(p - (s.a + t * d));
}

// Classes of the piece's corners and insets of its edges (Patch); `thinnest`
// is kThinnest of the patch's diameter.
void mark_discontinuities(Piece& piece, const Polygon2& polygon, const Polygon2& whole,
                          const Features& features, const dvec2& centroid, double thinnest) {
  const double near = 1e-3 * thinnest;
  const size_t n = polygon.size();
  piece.corner_class.assign(n, 0u);
  piece.edge_inset.assign(n, 0.0f);
  for (size_t i = 0; i < n; ++i) {
    const dvec2 v = polygon[i].p;
    // A point of the piece next to the corner says which side of each line
    // through it the piece lies on.
    const dvec2 inner = v + 1e-3 * (centroid - v);
    std::uint64_t signature = 0;
    bool on_line = false;
    for (size_t k = 0; k < features.covers.size(); ++k) {
      const auto& outline = features.covers[k].outline;
      bool on = false;
      for (size_t e = 0; e < outline.size() && !on; ++e)
        on = distance_to_segment(v, {outline[e], outline[(e + 1) % outline.size()]}) <= near;
      if (!on) continue;
      on_line = true;
      signature = signature * 1000003u + 2 * k + (inside(outline, inner, 0.0) ? 1 : 0);
    }
    for (size_t k = 0; k < features.meetings.size(); ++k) {
      const Segment& s = features.meetings[k].segment;
      if (distance_to_segment(v, s) > near) continue;
      on_line = true;
      const dvec2 d = s.b - s.a;
      const double t = glm::dot(inner - s.a, d) / glm::dot(d, d);
      const int side = t < 0.0 || t > 1.0 ? 2 : (cross2(d, inner - s.a) > 0.0 ? 1 : 0);
      signature = signature * 1000003u + 3 * (k + features.covers.size()) +
                  static_cast<std::uint64_t>(side);
    }
    if (on_line) piece.corner_class[i] = static_cast<std::uint32_t>(signature | 1u << 31);
    // Edges along the outline of a cover some gap away, and along a line
    // where another face passes through this one (a sample a millionth from
    // that face sees it edge-on: projecting it to find what it hides is then
    // ill-conditioned, and a plate through a wall let 1e-9 of the light behind
    // the wall through). Not along the face's own edges.
    const dvec2 w = polygon[(i + 1) % n].p;
    bool own_edge = false;
    for (size_t e = 0; e < whole.size() && !own_edge; ++e) {
      const Segment edge{whole[e].p, whole[(e + 1) % whole.size()].p};
      own_edge = distance_to_segment(v, edge) <= near && distance_to_segment(w, edge) <= near;
    }
    for (const Features::Meeting& m : features.meetings) {
      if (m.crosses && !own_edge && distance_to_segment(v, m.segment) <= near &&
          distance_to_segment(w, m.segment) <= near)
        piece.edge_inset[i] = std::max(piece.edge_inset[i], static_cast<float>(10.0 * thinnest));
    }
    for (const Features::Cover& cover : features.covers) {
      if (!(cover.gap > 0.0)) continue;
      for (size_t e = 0; e < cover.outline.size(); ++e) {
        const Segment edge{cover.outline[e], cover.outline[(e + 1) % cover.outline.size()]};
        if (distance_to_segment(v, edge) <= near && distance_to_segment(w, edge) <= near)
          piece.edge_inset[i] = std::max(piece.edge_inset[i], static_cast<float>(4.0 * cover.gap));
      }
    }
  }
}

// The convex polygon as triangles and quads, dropping corners that lie on
// the line of their neighbours (a cut that ended on an edge).
void append_patches(const Patch& source, const Piece& piece, std::vector<Patch>& out) {
  std::vector<dvec3> corners;
  std::vector<std::uint32_t> classes;
  std::vector<float> insets;  // of the edge leaving each kept corner
  const Polygon2& poly = piece.polygon;
  const double scale = std::sqrt(piece.area);
  for (size_t i = 0; i < poly.size(); ++i) {
    const dvec2& prev = poly[(i + poly.size() - 1) % poly.size()].p;
    const dvec2& here = poly[i].p;
    const dvec2& next = poly[(i + 1) % poly.size()].p;
    const bool dropped = glm::length(here - prev) <= 1e-9 * scale ||
                         cross2(here - prev, next - here) <=
                             1e-9 * glm::length(here - prev) * glm::length(next - here);
    if (dropped) {
      // The edge before it now runs on: it keeps an inset only if both had it.
      if (!insets.empty()) insets.back() = std::min(insets.back(), piece.edge_inset[i]);
      continue;
    }
    corners.push_back(poly[i].x);
    classes.push_back(piece.corner_class[i]);
    insets.push_back(piece.edge_inset[i]);
  }
  const size_t n = corners.size();
  const auto emit = [&](std::initializer_list<size_t> index) {
    Patch p = source;
    p.corner_count = static_cast<std::uint8_t>(index.size());
    size_t k = 0;
    for (size_t i : index) {
      p.corner_class[k] = classes[i];
      p.corners[k++] = corners[i];
    }
    const auto* first = index.begin();
    for (size_t e = 0; e < k; ++e) {
      const size_t a = first[e], b = first[(e + 1) % k];
      p.edge_inset[e] =
          (a + 1) % n == b ? insets[a] : 0.0f;  // along the piece's outline, not a diagonal
    }
    p.area = 0.5 * glm::length(twice_area_normal({p.corners.data(), k}));
    p.sides = piece.sides;
    if (p.area > 0.0) out.push_back(p);
  };
  if (n < 3) return;
  size_t i = 1;
  for (; i + 2 < n; i += 2) emit({0, i, i + 1, i + 2});
  if (i + 1 < n) emit({0, i, i + 1});
}

// The patches as triangles in a BVH, each triangle's patch in `owner`.
struct PatchBvh {
  SceneBvh bvh;
  std::vector<std::uint32_t> owner;
};

PatchBvh patch_bvh(const std::vector<Patch>& patches) {
  std::vector<Triangle> triangles;
  PatchBvh out;
  for (std::uint32_t p = 0; p < patches.size(); ++p) {
    const Patch& patch = patches[p];
    triangles.push_back({{patch.corners[0], patch.corners[1], patch.corners[2]}});
    out.owner.push_back(p);
    if (patch.corner_count == 4) {
      triangles.push_back({{patch.corners[0], patch.corners[2], patch.corners[3]}});
      out.owner.push_back(p);
    }
  }
  out.bvh = build_scene_bvh(triangles);
  return out;
}

// The patches of other surfaces near patch p that may cut it, sorted (into
// `near`). A face that casts no shadow (a Blender light) neither cuts nor is cut.
void near_patches(const std::vector<Patch>& patches, const PatchBvh& found, size_t p,
                  double margin_size, std::vector<std::uint32_t>& near) {
  const Patch& patch = patches[p];
  near.clear();
  if (!patch.occludes) return;
  Aabb box;
  for (int k = 0; k < patch.corner_count; ++k) box.grow(patch.corners[static_cast<size_t>(k)]);
  const dvec3 margin(margin_size);
  box.lo -= margin;
  box.hi += margin;
  traverse_scene_bvh(
      found.bvh,
      [&](const Aabb& b) {
        return b.lo.x <= box.hi.x && b.hi.x >= box.lo.x && b.lo.y <= box.hi.y &&
               b.hi.y >= box.lo.y && b.lo.z <= box.hi.z && b.hi.z >= box.lo.z;
      },
      [&](std::uint32_t t) {
        const std::uint32_t q = found.owner[t];
        if (q != p && patches[q].surface != patch.surface && patches[q].occludes) near.push_back(q);
      });
  std::sort(near.begin(), near.end());
  near.erase(std::unique(near.begin(), near.end()), near.end());
}

// Patch p cut along where the patches `near` it touch, cross or cover it:
// its pieces, each with the discontinuities at its edges and corners and the
// earlier-or-later patches it coincides with.
std::vector<Piece> cut_patch(const std::vector<Patch>& patches, size_t p,
                             const std::vector<std::uint32_t>& near,
                             const std::vector<double>& diameter, double scene_diameter) {
  const Patch& patch = patches[p];
  const Frame f = frame_of(patch);
  const double thinnest = kThinnest * diameter[p];
  std::vector<Cut> cuts;
  std::vector<std::pair<std::uint32_t, std::vector<dvec2>>> coincident;
  Features features;
  const double touch_p = kCoincidentScene * scene_diameter;
  Polygon2 whole;
  for (int k = 0; k < patch.corner_count; ++k)
    whole.push_back(
        {f.to2(patch.corners[static_cast<size_t>(k)]), patch.corners[static_cast<size_t>(k)]});
  const std::vector<dvec2> outline_p = points_of(whole);
  for (std::uint32_t q : near) {
    Contact c = contact_of(f, outline_p, diameter[p], patches[q], diameter[q], scene_diameter);
    // Around a light every piece counts (what lies behind it is bright);
    // elsewhere a strip narrower than kNarrowest is left uncut.
    const double narrowest = emits(patches[q]) ? thinnest : kNarrowest * diameter[p];
    for (const Segment& segment : c.cuts)
      if (glm::length(segment.b - segment.a) > thinnest) cuts.push_back({segment, narrowest});
    if (c.meets) features.meetings.push_back({c.cuts[0], c.crosses});
    if (!c.cover_outline.empty()) {
      features.covers.push_back(
          {c.cover_outline, c.gap > std::max(touch_p, kCoincident * diameter[p]) ? c.gap : 0.0});
      if (c.coincident) coincident.emplace_back(q, std::move(c.cover_outline));
    }
  }
  std::vector<Piece> out;
  for (Polygon2& polygon : cut_along(whole, std::move(cuts), thinnest)) {
    Piece piece;
    const std::vector<dvec2> points = points_of(polygon);
    piece.area = std::abs(signed_area(points));
    const dvec2 c = centroid_of(points);
    piece.centre = f.origin + c.x * f.u + c.y * f.v;
    for (const auto& [q, outline] : coincident)
      if (inside(outline, c, thinnest)) piece.coincides_with.push_back(q);
    mark_discontinuities(piece, polygon, whole, features, c, thinnest);
    piece.polygon = std::move(polygon);
    piece.sides = patch.sides;
    out.push_back(std::move(piece));
  }
  return out;
}

// Coinciding pieces: the later patch's piece goes into the earlier's (its
// merged_into set, its sides given to the earlier piece's where those are
// missing or dark). Returns the pairs of input faces that are the same
// surface twice, sorted.
std::vector<std::array<std::uint32_t, 2>> merge_coincident_pieces(
    const std::vector<Patch>& patches, std::vector<std::vector<Piece>>& cut,
    const std::vector<double>& diameter) {
  const size_t n = patches.size();
  std::vector<size_t> first_piece(n + 1, 0);
  for (size_t p = 0; p < n; ++p) first_piece[p + 1] = first_piece[p] + cut[p].size();
  std::vector<Piece*> flat;
  for (auto& pieces : cut)
    for (Piece& piece : pieces) flat.push_back(&piece);
  const auto resolve = [&](std::int64_t index) {
    while (flat[static_cast<size_t>(index)]->merged_into >= 0)
      index = flat[static_cast<size_t>(index)]->merged_into;
    return index;
  };
  std::vector<std::array<std::uint32_t, 2>> coincident;
  for (size_t p = 0; p < n; ++p) {
    for (size_t k = 0; k < cut[p].size(); ++k) {
      Piece& piece = cut[p][k];
      std::int64_t target = -1;
      std::uint32_t found_in = 0;  // the patch of the piece it coincides with
      for (std::uint32_t q : piece.coincides_with) {
        if (q >= p) break;  // sorted: only earlier patches
        const double tolerance = kThinnest * std::max(diameter[p], diameter[q]);
        for (size_t m = 0; m < cut[q].size() && target < 0; ++m) {
          const Piece& other = cut[q][m];
          if (glm::length(other.centre - piece.centre) <= tolerance &&
              std::abs(other.area - piece.area) <= 1e-3 * std::max(other.area, piece.area))
            target = static_cast<std::int64_t>(first_piece[q] + m);
        }
        if (target >= 0) {
          found_in = q;
          break;
        }
      }
      if (target < 0) continue;
      // Named only where the two face the same way: the same surface twice
      // (z-fighting). Faces facing each other are solids touching (a box on a
      // floor, a board against a shelf's side), hidden between them.
      if (glm::dot(patches[p].normal, patches[found_in].normal) > 0.0)
        coincident.push_back({std::min(patches[p].sides[0].face, patches[found_in].sides[0].face),
                              std::max(patches[p].sides[0].face, patches[found_in].sides[0].face)});
      target = resolve(target);
      Piece& into = *flat[static_cast<size_t>(target)];
      const size_t owner_patch = static_cast<size_t>(
          std::upper_bound(first_piece.begin(), first_piece.end(), static_cast<size_t>(target)) -
          first_piece.begin() - 1);
      const bool same_facing = glm::dot(patches[p].normal, patches[owner_patch].normal) > 0.0;
      for (size_t s = 0; s < 2; ++s) {
        const PatchSide& side = piece.sides[s];
        if (!side.present) continue;
        PatchSide& there = into.sides[same_facing ? s : 1 - s];
        const bool emits = luminance(side.emission) > 0.0,
                   there_emits = luminance(there.emission) > 0.0;
        if (!there.present || (emits && !there_emits)) there = side;
      }
      piece.merged_into = target;
    }
  }
  std::sort(coincident.begin(), coincident.end());
  coincident.erase(std::unique(coincident.begin(), coincident.end()), coincident.end());
  return coincident;
}

// The patches as they were before cutting, but for those whose every piece
// went into another's.
std::vector<Patch> unmerged_patches(const std::vector<Patch>& patches,
                                    const std::vector<std::vector<Piece>>& cut) {
  std::vector<Patch> out;
  for (size_t p = 0; p < patches.size(); ++p) {
    const bool merged = std::all_of(cut[p].begin(), cut[p].end(),
                                    [](const Piece& piece) { return piece.merged_into >= 0; });
    if (!merged) out.push_back(patches[p]);
  }
  return out;
}

// The pieces not merged into others as patches: a patch left whole keeps its
// corners and takes its piece's sides and discontinuities. The surfaces of
// the patches cut into several pieces are added to `split_surfaces`.
std::vector<Patch> patches_of_pieces(const std::vector<Patch>& patches,
                                     const std::vector<std::vector<Piece>>& cut,
                                     std::vector<std::uint32_t>& split_surfaces) {
  std::vector<Patch> out;
  out.reserve(patches.size());
  for (size_t p = 0; p < patches.size(); ++p) {
    if (cut[p].size() == 1 && cut[p][0].merged_into < 0) {
      Patch whole = patches[p];
      const Piece& piece = cut[p][0];
      whole.sides = piece.sides;
      for (int k = 0; k < whole.corner_count; ++k) {
        whole.corner_class[static_cast<size_t>(k)] = piece.corner_class[static_cast<size_t>(k)];
        whole.edge_inset[static_cast<size_t>(k)] = piece.edge_inset[static_cast<size_t>(k)];
      }
      out.push_back(whole);
      continue;
    }
    if (cut[p].size() > 1) split_surfaces.push_back(patches[p].surface);
    for (const Piece& piece : cut[p])
      if (piece.merged_into < 0) append_patches(patches[p], piece, out);
  }
  return out;
}

}  // namespace

void mesh_contacts(Scene& scene) {
  std::vector<Patch>& patches = scene.patches;
  const size_t n = patches.size();
  if (n < 2) {
    scene.occluders = patches;
    return;
  }
  const PatchBvh found = patch_bvh(patches);
  std::vector<double> diameter(n);
  for (size_t p = 0; p < n; ++p) diameter[p] = diameter_of(patches[p]);

  // Each patch cut on its own, in parallel: deterministic.
  std::vector<std::vector<Piece>> cut(n);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n), [&](const auto& range) {
    std::vector<std::uint32_t> near;
    for (size_t p = range.begin(); p != range.end(); ++p) {
      const double margin = kCoverGap * diameter[p] + kCoincidentScene * scene.diameter;
      near_patches(patches, found, p, margin, near);
      cut[p] = cut_patch(patches, p, near, diameter, scene.diameter);
    }
  });
  scene.coincident = merge_coincident_pieces(patches, cut, diameter);

  scene.occluders = unmerged_patches(patches, cut);
  std::vector<std::uint32_t> split_surfaces;
  patches = patches_of_pieces(patches, cut, split_surfaces);
  std::sort(split_surfaces.begin(), split_surfaces.end());
  scene.split_faces = static_cast<size_t>(
      std::unique(split_surfaces.begin(), split_surfaces.end()) - split_surfaces.begin());
}

}  // namespace radiosity
