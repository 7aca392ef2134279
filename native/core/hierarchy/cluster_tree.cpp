#include "core/hierarchy/cluster_tree.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace radiosity {
namespace {

// Which of the six axis directions the normal is closest to.
int facing_class(const dvec3& n) {
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (std::abs(n[k]) > std::abs(n[axis])) axis = k;
  return 2 * axis + (n[axis] < 0.0 ? 1 : 0);
}

// The second moment of a triangle's area about the origin: the integral of
// x x^T, (A / 12) (sum of v v^T + s s^T) with s the sum of its corners.
glm::dmat3 triangle_moment(const dvec3& a, const dvec3& b, const dvec3& c) {
  const double area = 0.5 * glm::length(glm::cross(b - a, c - a));
  const dvec3 s = a + b + c;
  return area / 12.0 *
         (glm::outerProduct(a, a) + glm::outerProduct(b, b) + glm::outerProduct(c, c) +
          glm::outerProduct(s, s));
}

}  // namespace

glm::dmat3 ClusterNode::covariance_matrix() const {
  const auto& c = covariance;
  return glm::dmat3(c[0], c[1], c[2], c[1], c[3], c[4], c[2], c[4], c[5]);
}

ClusterTree::ClusterTree(const Hierarchy& hierarchy, std::span<const std::uint8_t> left_out) {
  for (std::uint32_t p = 0; p < hierarchy.scene().patches.size(); ++p) {
    for (int side = 0; side < 2; ++side) {
      const std::int32_t root = hierarchy.root(p, side);
      if (root == kNone || (!left_out.empty() && left_out[static_cast<std::size_t>(root)] != 0))
        continue;
      const Element& e = hierarchy.element(root);
      if (luminance(hierarchy.reflectance(e)) > 0.0 || luminance(hierarchy.emission(e)) > 0.0)
        sides_.push_back(root);
    }
  }
  if (sides_.empty()) return;
  nodes_.reserve(2 * sides_.size());
  build(hierarchy, 0, static_cast<std::uint32_t>(sides_.size()));
  area_prefix_.assign(sides_.size() + 1, 0.0);
  for (size_t i = 0; i < sides_.size(); ++i)
    area_prefix_[i + 1] = area_prefix_[i] + hierarchy.element(sides_[i]).area;
}

std::int32_t ClusterTree::build(const Hierarchy& hierarchy, std::uint32_t first,
                                std::uint32_t count) {
  const auto index = static_cast<std::int32_t>(nodes_.size());
  nodes_.emplace_back();
  const auto begin = sides_.begin() + first, end = begin + count;

  ClusterNode node;
  node.first = first;
  node.count = count;
  dvec3 lo(std::numeric_limits<double>::infinity()), hi = -lo;
  dvec3 weighted_normal(0.0);
  for (auto it = begin; it != end; ++it) {
    const Element& e = hierarchy.element(*it);
    dvec3 corners[4];
    const int n = hierarchy.corners(e, corners);
    for (int k = 0; k < n; ++k) {
      lo = glm::min(lo, corners[k]);
      hi = glm::max(hi, corners[k]);
    }
    weighted_normal += e.area * hierarchy.normal(e);
    node.centre += e.area * hierarchy.centre(e);
    node.area += e.area;
    node.reflects |= luminance(hierarchy.reflectance(e)) > 0.0;
    node.reflectance =
        std::max(node.reflectance, static_cast<float>(luminance(hierarchy.reflectance(e))));
    node.sends |=
        luminance(hierarchy.reflectance(e)) > 0.0 || luminance(hierarchy.emission(e)) > 0.0;
    node.emits |= luminance(hierarchy.emission(e)) > 0.0;
  }
  node.centre = node.area > 0.0 ? node.centre / node.area : 0.5 * (lo + hi);
  glm::dmat3 moment(0.0);  // of the area about the centre
  for (auto it = begin; it != end; ++it) {
    dvec3 corners[4];
    const int n = hierarchy.corners(hierarchy.element(*it), corners);
    for (int k = 0; k < n; ++k) {
      corners[k] -= node.centre;
      node.radius = std::max(node.radius, glm::length(corners[k]));
    }
    for (int k = 1; k + 1 < n; ++k)
      moment += triangle_moment(corners[0], corners[k], corners[k + 1]);
  }
  if (node.area > 0.0) {
    const glm::dmat3 c = moment / node.area;
    node.covariance = {static_cast<float>(c[0][0]), static_cast<float>(c[0][1]),
                       static_cast<float>(c[0][2]), static_cast<float>(c[1][1]),
                       static_cast<float>(c[1][2]), static_cast<float>(c[2][2])};
  }
  node.area_normal = weighted_normal;
  const double length = glm::length(weighted_normal);
  node.axis = length > 0.0 ? weighted_normal / length : hierarchy.normal(hierarchy.element(*begin));
  for (auto it = begin; it != end; ++it) {
    const double c =
        std::clamp(glm::dot(node.axis, hierarchy.normal(hierarchy.element(*it))), -1.0, 1.0);
    node.spread = std::max(node.spread, std::acos(c));
  }
  node.height_lo = std::numeric_limits<double>::infinity();
  node.height_hi = -node.height_lo;
  for (auto it = begin; it != end; ++it) {
    dvec3 corners[4];
    const int n = hierarchy.corners(hierarchy.element(*it), corners);
    for (int k = 0; k < n; ++k) {
      node.height_lo = std::min(node.height_lo, glm::dot(node.axis, corners[k]));
      node.height_hi = std::max(node.height_hi, glm::dot(node.axis, corners[k]));
    }
  }

  if (count > 1) {
    // Emitting sides apart from the others (so a cluster's light is its
    // sides' own, not a lamp's averaged with the ceiling around it), then
    // facing classes (sides in one class face within 55 degrees of an axis),
    // then halves along the longest extent of the centres.
    const auto class_of = [&](std::int32_t e) {
      const Element& x = hierarchy.element(e);
      return facing_class(hierarchy.normal(x)) + (luminance(hierarchy.emission(x)) > 0.0 ? 6 : 0);
    };
    std::stable_sort(begin, end,
                     [&](std::int32_t a, std::int32_t b) { return class_of(a) < class_of(b); });
    std::uint32_t half = 0;
    if (class_of(*begin) != class_of(*(end - 1))) {
      // The class boundary nearest the middle.
      std::uint32_t best = count;
      for (std::uint32_t i = 1; i < count; ++i) {
        if (class_of(*(begin + i)) == class_of(*(begin + i - 1))) continue;
        const auto distance = [&](std::uint32_t k) {
          return k > count / 2 ? k - count / 2 : count / 2 - k;
        };
        if (best == count || distance(i) < distance(best)) best = i;
      }
      half = best;
    } else {
      // Halves along the longest extent of a point in six dimensions: the
      // side's centre, and its normal times the node's radius (so a curved
      // or dented surface is cut where its normals turn as readily as where
      // it runs on: clusters that face one way link as clusters sooner).
      const auto coordinate = [&](std::int32_t e, int k) {
        const Element& x = hierarchy.element(e);
        return k < 3 ? hierarchy.centre(x)[k] : node.radius * hierarchy.normal(x)[k - 3];
      };
      double low[6], high[6];
      std::fill(low, low + 6, std::numeric_limits<double>::infinity());
      std::fill(high, high + 6, -std::numeric_limits<double>::infinity());
      for (auto it = begin; it != end; ++it)
        for (int k = 0; k < 6; ++k) {
          low[k] = std::min(low[k], coordinate(*it, k));
          high[k] = std::max(high[k], coordinate(*it, k));
        }
      int axis = 0;
      for (int k = 1; k < 6; ++k)
        if (high[k] - low[k] > high[axis] - low[axis]) axis = k;
      half = count / 2;
      // Ties broken by element id: the tree does not depend on the sort's luck.
      std::nth_element(begin, begin + half, end, [&](std::int32_t a, std::int32_t b) {
        const double ca = coordinate(a, axis), cb = coordinate(b, axis);
        return ca < cb || (ca == cb && a < b);
      });
    }
    node.child[0] = build(hierarchy, first, half);
    node.child[1] = build(hierarchy, first + half, count - half);
  }
  nodes_[static_cast<size_t>(index)] = node;
  return index;
}

std::size_t ClusterTree::memory_bytes() const {
  return nodes_.capacity() * sizeof(ClusterNode) + sides_.capacity() * sizeof(std::int32_t) +
         area_prefix_.capacity() * sizeof(double);
}

}  // namespace radiosity
