// Clusters of patch sides (Smits, Arvo and Greenberg 1994; Sillion 1995): a
// binary tree over the top-level elements, split first by which way they face
// (six classes: the largest component of the normal and its sign), then by
// position. A cluster of sides that all face one way has a narrow cone of
// normals, so a whole cluster can be found facing towards or away from
// another and exchange light with it through one link (cluster_links.h).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "core/hierarchy/hierarchy.h"

namespace radiosity {

struct ClusterNode {
  dvec3 centre{0.0};       // area-weighted centroid of its sides
  double radius = 0.0;     // of the sphere about `centre` holding every side
  dvec3 axis{0.0};         // of the normals' cone (area-weighted mean normal)
  dvec3 area_normal{0.0};  // sum of its sides' area times normal
  double spread = 0.0;     // the cone's half-angle, radians
  // Heights of its sides' corners along `axis`: where every side faces along
  // the axis (is_flat: a floor, a tiled wall), a side sees only what rises
  // above its own plane (cluster_links.cpp prunes coplanar pairs with this).
  double height_lo = 0.0, height_hi = 0.0;
  bool is_flat() const { return spread < kFlatSpread; }
  static constexpr double kFlatSpread = 1e-6;  // radians
  double area = 0.0;
  // How its area spreads about `centre`: the covariance of a uniform point of
  // its sides (xx, xy, xz, yy, yz, zz), for the second-order correction of
  // cluster links (cluster_links.h).
  std::array<float, 6> covariance{};
  glm::dmat3 covariance_matrix() const;
  float reflectance = 0.0f;  // the largest luminance of its sides' reflectance
  std::int32_t child[2] = {kNone, kNone};
  std::uint32_t first = 0, count = 0;  // its sides: ClusterTree::sides()[first, first + count)
  bool reflects = false;               // some side reflects (can receive)
  bool sends = false;                  // some side emits or reflects
  bool emits = false;                  // some side emits
  bool is_leaf() const { return child[0] == kNone; }
};

class ClusterTree {
 public:
  // Over every top-level element that reflects or emits, but those marked in
  // `left_out` (per element, or empty: none).
  explicit ClusterTree(const Hierarchy& hierarchy, std::span<const std::uint8_t> left_out = {});
  ClusterTree() = default;

  const std::vector<ClusterNode>& nodes() const { return nodes_; }
  const ClusterNode& node(std::int32_t n) const { return nodes_[static_cast<size_t>(n)]; }
  std::int32_t root() const { return nodes_.empty() ? kNone : 0; }
  // Top-level element ids in tree order; a leaf holds exactly one.
  const std::vector<std::int32_t>& sides() const { return sides_; }
  // Cumulative area of sides()[0, i): area-proportional sampling within a node.
  const std::vector<double>& area_prefix() const { return area_prefix_; }
  std::size_t memory_bytes() const;
  // Gives the memory back (no cluster links: the tree is not needed any more).
  void release() { *this = ClusterTree(); }

 private:
  std::int32_t build(const Hierarchy& hierarchy, std::uint32_t first, std::uint32_t count);

  std::vector<ClusterNode> nodes_;
  std::vector<std::int32_t> sides_;
  std::vector<double> area_prefix_;
};

}  // namespace radiosity
