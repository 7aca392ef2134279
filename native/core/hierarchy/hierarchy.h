// The element hierarchy (DESIGN s5): every side of every patch is the root of a
// tree of elements; a quad splits into four at its edge midpoints, a triangle
// into four likewise. Elements refer to corner vertices in one pool, shared
// between neighbours of the same patch side, so the output mesh can be stitched
// at hanging vertices. Radiosity is sampled at each element's corners and centre.
#pragma once

#include <array>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "radiosity/color.h"
#include "radiosity/scene.h"
#include "radiosity/vec.h"

namespace radiosity {

inline constexpr int kMaxSamples = 5;  // 4 corners and the centre
inline constexpr std::int32_t kNone = -1;

struct Element {
  std::array<std::uint32_t, 4> corner{};  // vertex ids, counter-clockwise about the side's normal
  std::int32_t parent = kNone;
  std::int32_t first_child = kNone;  // the four children are consecutive
  std::uint32_t patch = 0;
  std::uint8_t side = 0;          // 0 front, 1 back
  std::uint8_t corner_count = 0;  // 3 or 4; samples = corner_count + 1 (centre last)
  std::uint8_t has_links = 0;     // a link ends on this element or an ancestor
  double area = 0.0;
  Rgb radiance{0.0};  // area average, L_e + rho H

  int sample_count() const { return corner_count + 1; }
  bool is_leaf() const { return first_child == kNone; }
};

// Weights of an element's samples (corners, then centre) in the area average
// of its interpolant: what the element gathers in all is its area times
// sum_k w[k] v[k].
using AverageWeights = std::array<double, kMaxSamples>;

// The element's interpolant of sample values (DESIGN s5): bilinear or
// barycentric through the corners plus a bubble that vanishes on the edges and
// matches the centre sample. Continuous across edges.
struct Interpolant {
  // Value at child `c`'s sample `s` of a parent with `corner_count` corners
  // (clamped at zero).
  static Rgb at_child_sample(int corner_count, const std::array<Rgb, kMaxSamples>& values, int c,
                             int s);
  // Average weights where area is spread evenly over the parameters: every
  // triangle, and quads that are parallelograms.
  static AverageWeights uniform_weights(int corner_count);
  // A quad's average weights, from its area density at the corners (the
  // bilinear map's Jacobian, Hierarchy::average_weights): a quad that is not a
  // parallelogram gives the parameters near its wide end more area.
  static AverageWeights quad_weights(const std::array<double, 4>& corner_density);
  static Rgb average(const AverageWeights& weights, int corner_count,
                     const std::array<Rgb, kMaxSamples>& values);
};

class Hierarchy {
 public:
  explicit Hierarchy(const Scene& scene);

  const Scene& scene() const { return *scene_; }
  std::vector<Element>& elements() { return elements_; }
  const std::vector<Element>& elements() const { return elements_; }
  const Element& element(std::int32_t e) const { return elements_[static_cast<size_t>(e)]; }
  Element& element(std::int32_t e) { return elements_[static_cast<size_t>(e)]; }
  const dvec3& vertex(std::uint32_t v) const { return vertices_[v]; }
  std::size_t vertex_count() const { return vertices_.size(); }

  // Root element of each side of a patch (kNone for the back of one-sided patches).
  std::int32_t root(std::uint32_t patch, int side) const { return roots_[2 * patch + side]; }
  std::size_t root_count() const { return roots_.size(); }

  const Patch& patch_of(const Element& e) const { return scene_->patches[e.patch]; }
  // Unit normal of the element's side.
  dvec3 normal(const Element& e) const {
    return e.side == 0 ? patch_of(e).normal : -patch_of(e).normal;
  }
  const PatchSide& side_of(const Element& e) const { return patch_of(e).sides[e.side]; }
  Rgb reflectance(const Element& e) const { return side_of(e).reflectance; }
  Rgb emission(const Element& e) const { return side_of(e).emission; }
  // Whether the element's side reflects light (can receive it).
  bool reflects(const Element& e) const { return luminance(reflectance(e)) > 0.0; }

  // Corner positions, counter-clockwise about the side's normal.
  int corners(const Element& e, dvec3* out) const;
  // The area average of the element's interpolant (Interpolant), over its
  // true area: the four children of a quad that is not a parallelogram differ
  // in area, and so do the parts of each.
  AverageWeights average_weights(const Element& e) const;
  Rgb average(const Element& e, const std::array<Rgb, kMaxSamples>& values) const {
    return Interpolant::average(average_weights(e), e.corner_count, values);
  }
  dvec3 centre(const Element& e) const;
  double diameter(const Element& e) const;
  // Sample points: corners pulled towards the centre by a millionth of the
  // element's size, so a corner on an edge shared with an emitter keeps a finite
  // gradient (MATH.md s3), then the centre. Returns the count.
  int samples(const Element& e, dvec3* out) const;
  // Whether some corner sample of the element may sit further in, off a
  // contact line (Patch::edge_inset).
  bool has_insets(const Element& e) const {
    const auto& inset = patch_of(e).edge_inset;
    return inset[0] > 0.0f || inset[1] > 0.0f || inset[2] > 0.0f || inset[3] > 0.0f;
  }
  // Whether some corner sample of the element does sit further in: a corner
  // on an inset edge. Elements inside such a patch sample as any other.
  bool samples_inset(const Element& e) const;

  // Splits a leaf into four children (no-op if already split); returns the
  // first child. Children inherit the parent's radiance.
  std::int32_t subdivide(std::int32_t e);

  // The vertex halfway between two vertices, if some element created it.
  std::int32_t midpoint(std::uint32_t a, std::uint32_t b) const;

  // Releases the unused capacity of the element and vertex arrays.
  void shrink_to_fit() {
    elements_.shrink_to_fit();
    vertices_.shrink_to_fit();
  }
  std::size_t memory_bytes() const;

 private:
  std::uint32_t add_vertex(const dvec3& p);
  std::uint32_t midpoint_or_add(std::uint32_t a, std::uint32_t b);
  static std::uint64_t edge_key(std::uint32_t a, std::uint32_t b);

  const Scene* scene_;
  std::vector<Element> elements_;
  std::vector<dvec3> vertices_;
  std::vector<std::int32_t> roots_;
  std::unordered_map<std::uint64_t, std::uint32_t> midpoints_;
};

}  // namespace radiosity
