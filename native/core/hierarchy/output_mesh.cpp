#include <algorithm>
#include <cmath>
#include <glm/gtc/type_precision.hpp>
#include <map>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "core/hierarchy/make_output_mesh.h"

namespace radiosity {
namespace {

// Appends the vertices strictly between a and b that finer elements created.
void append_hanging(const Hierarchy& h, std::uint32_t a, std::uint32_t b,
                    std::vector<std::uint32_t>& out) {
  const std::int32_t m = h.midpoint(a, b);
  if (m == kNone) return;
  const auto mid = static_cast<std::uint32_t>(m);
  append_hanging(h, a, mid, out);
  out.push_back(mid);
  append_hanging(h, mid, b, out);
}

// Vertices of other top-level elements of the same surface side (the pieces
// of a face split by contact.h, the triangles of an n-gon) that lie inside
// the edges of an element: where pieces were cut at different places, a
// corner of one lies on the edge of another (a T-junction), which the coarser
// polygon must include to meet it without a crack.
class ForeignVertices {
 public:
  explicit ForeignVertices(const Hierarchy& h);
  // Appends, in order from a towards b, the foreign vertices strictly between
  // the consecutive vertices a and b of a polygon of the element under `root`.
  void append_between(std::int32_t root, std::uint32_t a, std::uint32_t b,
                      std::vector<std::uint32_t>& out) const;

 private:
  struct OnEdge {
    int edge;
    double t;
  };
  struct RootEdges {
    std::unordered_map<std::uint32_t, std::vector<OnEdge>> own;            // its boundary vertices
    std::array<std::vector<std::pair<double, std::uint32_t>>, 4> foreign;  // per edge, sorted by t
  };
  std::unordered_map<std::int32_t, RootEdges> roots_;  // only roots that meet foreign vertices
};

void boundary_chain(const Hierarchy& h, std::uint32_t a, std::uint32_t b,
                    std::vector<std::uint32_t>& out) {
  out.push_back(a);
  append_hanging(h, a, b, out);
}

ForeignVertices::ForeignVertices(const Hierarchy& h) {
  const Scene& scene = h.scene();
  // Top-level elements grouped by the side of the input face they show.
  std::map<std::pair<std::uint32_t, std::uint8_t>, std::vector<std::int32_t>> groups;
  for (std::uint32_t p = 0; p < scene.patches.size(); ++p) {
    for (int side = 0; side < 2; ++side) {
      const std::int32_t root = h.root(p, side);
      if (root == kNone) continue;
      const PatchSide& shown = h.side_of(h.element(root));
      groups[{shown.face, shown.face_side}].push_back(root);
    }
  }
  std::vector<std::uint32_t> chain;
  for (const auto& [key, roots] : groups) {
    if (roots.size() < 2) continue;
    // Every boundary vertex of the group, in a grid of about one cell per
    // top-level element edge.
    std::vector<std::uint32_t> vertices;
    double edge_sum = 0.0;
    size_t edges = 0;
    for (std::int32_t r : roots) {
      const Element& e = h.element(r);
      for (int k = 0; k < e.corner_count; ++k) {
        const std::uint32_t a = e.corner[static_cast<size_t>(k)],
                            b = e.corner[static_cast<size_t>((k + 1) % e.corner_count)];
        chain.clear();
        boundary_chain(h, a, b, chain);
        vertices.insert(vertices.end(), chain.begin(), chain.end());
        edge_sum += glm::length(h.vertex(b) - h.vertex(a));
        ++edges;
      }
    }
    std::sort(vertices.begin(), vertices.end());
    vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
    const double cell = edge_sum / static_cast<double>(edges);
    const auto cell_of = [&](const dvec3& p) { return glm::i64vec3(glm::floor(p / cell)); };
    struct CellHash {
      size_t operator()(const glm::i64vec3& c) const {
        // Unsigned: the products of far cells overflow (UBSan, make fuzz's scene harness).
        const glm::u64vec3 u(c);
        return static_cast<size_t>(u.x * 73856093u ^ u.y * 19349663u ^ u.z * 83492791u);
      }
    };
    std::unordered_map<glm::i64vec3, std::vector<std::uint32_t>, CellHash> grid;
    for (std::uint32_t v : vertices) grid[cell_of(h.vertex(v))].push_back(v);
    for (std::int32_t r : roots) {
      const Element& e = h.element(r);
      RootEdges found;
      bool any = false;
      for (int k = 0; k < e.corner_count; ++k) {
        const std::uint32_t a = e.corner[static_cast<size_t>(k)],
                            b = e.corner[static_cast<size_t>((k + 1) % e.corner_count)];
        const dvec3 pa = h.vertex(a), ab = h.vertex(b) - pa;
        const double length2 = glm::dot(ab, ab);
        chain.clear();
        boundary_chain(h, a, b, chain);
        chain.push_back(b);
        for (std::uint32_t v : chain)
          found.own[v].push_back({k, glm::dot(h.vertex(v) - pa, ab) / length2});
        const double tolerance = 1e-9 * std::sqrt(length2);
        const glm::i64vec3 lo = cell_of(glm::min(pa, pa + ab) - dvec3(tolerance));
        const glm::i64vec3 hi = cell_of(glm::max(pa, pa + ab) + dvec3(tolerance));
        std::vector<std::pair<double, std::uint32_t>>& list = found.foreign[static_cast<size_t>(k)];
        for (auto x = lo.x; x <= hi.x; ++x)
          for (auto y = lo.y; y <= hi.y; ++y)
            for (auto z = lo.z; z <= hi.z; ++z) {
              const auto it = grid.find({x, y, z});
              if (it == grid.end()) continue;
              for (std::uint32_t v : it->second) {
                if (std::find(chain.begin(), chain.end(), v) != chain.end()) continue;
                const dvec3 d = h.vertex(v) - pa;
                const double t = glm::dot(d, ab) / length2;
                if (t <= 1e-9 || t >= 1.0 - 1e-9) continue;
                if (glm::length(d - t * ab) > tolerance) continue;
                list.emplace_back(t, v);
              }
            }
        std::sort(list.begin(), list.end());
        list.erase(std::unique(list.begin(), list.end()), list.end());
        any |= !list.empty();
      }
      if (any) roots_.emplace(r, std::move(found));
    }
  }
}

void ForeignVertices::append_between(std::int32_t root, std::uint32_t a, std::uint32_t b,
                                     std::vector<std::uint32_t>& out) const {
  const auto it = roots_.find(root);
  if (it == roots_.end()) return;
  const RootEdges& r = it->second;
  const auto on_a = r.own.find(a), on_b = r.own.find(b);
  if (on_a == r.own.end() || on_b == r.own.end()) return;
  for (const OnEdge& ea : on_a->second) {
    for (const OnEdge& eb : on_b->second) {
      if (ea.edge != eb.edge) continue;
      const auto& list = r.foreign[static_cast<size_t>(ea.edge)];
      const double lo = std::min(ea.t, eb.t), hi = std::max(ea.t, eb.t);
      const size_t before = out.size();
      for (const auto& [t, v] : list)
        if (t > lo && t < hi) out.push_back(v);
      if (ea.t > eb.t) std::reverse(out.begin() + static_cast<std::ptrdiff_t>(before), out.end());
      return;
    }
  }
}

// Whether each side of each patch is output (index 2 patch + side): a side is
// shown when light reaches it or it emits (the back of a two-sided lamp seen
// from above); a face that no light reaches shows its front, dark, so the
// geometry stays whole.
std::vector<std::uint8_t> shown_sides(const Hierarchy& h) {
  const Scene& scene = h.scene();
  std::vector<std::uint8_t> lit(2 * scene.patches.size(), 0);
  for (const Element& e : h.elements()) lit[2 * e.patch + e.side] |= e.has_links;
  std::vector<std::uint8_t> shown(lit.size(), 0);
  for (std::uint32_t patch = 0; patch < scene.patches.size(); ++patch) {
    for (int side = 0; side < 2; ++side) {
      const size_t k = 2 * patch + static_cast<size_t>(side);
      if (h.root(patch, side) == kNone) continue;
      shown[k] = lit[k] ||
                 luminance(scene.patches[patch].sides[static_cast<size_t>(side)].emission) > 0.0 ||
                 (side == 0 && !lit[2 * patch + 1]);
    }
  }
  return shown;
}

// Radiance and gathered H (before rho and L_e) at the pool's vertices: the
// mean over the shown leaves that have it as a corner.
class VertexValues {
 public:
  VertexValues(const Hierarchy& h, const std::vector<std::array<Rgb, kMaxSamples>>& leaf_irradiance,
               const std::vector<std::uint8_t>& shown)
      : sums_(h.vertex_count()) {
    const auto& elements = h.elements();
    for (size_t i = 0; i < elements.size(); ++i) {
      const Element& e = elements[i];
      if (!e.is_leaf() || !shown[2 * e.patch + e.side]) continue;
      const Rgb rho = h.reflectance(e), emission = h.emission(e);
      for (int k = 0; k < e.corner_count; ++k) {
        // Energy-conserving link corrections (link_transport.cpp) may leave a
        // sample a rounding below zero; light is never negative.
        const Rgb gathered = glm::max(leaf_irradiance[i][static_cast<size_t>(k)], Rgb(0.0));
        Sum& sum = sums_[e.corner[static_cast<size_t>(k)]];
        sum.radiance += glm::dvec3(emission + rho * gathered);
        sum.gathered += glm::dvec3(gathered);
        ++sum.count;
      }
    }
  }
  glm::dvec3 radiance(std::uint32_t v) const {
    return sums_[v].count ? sums_[v].radiance / static_cast<double>(sums_[v].count)
                          : glm::dvec3(0.0);
  }
  glm::dvec3 gathered(std::uint32_t v) const {
    return sums_[v].count ? sums_[v].gathered / static_cast<double>(sums_[v].count)
                          : glm::dvec3(0.0);
  }

 private:
  struct Sum {
    glm::dvec3 radiance{0.0}, gathered{0.0};
    std::uint32_t count = 0;
  };
  std::vector<Sum> sums_;
};

// The output mesh's vertices as they are made: each pool vertex once, and a
// foreign vertex on a polygon's edge with that polygon's values.
class OutputVertices {
 public:
  OutputVertices(const Hierarchy& h, const VertexValues& values, OutputMesh& mesh)
      : h_(h), values_(values), mesh_(mesh), remap_(h.vertex_count(), kNone) {}

  // The output index of pool vertex v.
  std::int32_t pool(std::uint32_t v) {
    if (remap_[v] == kNone) remap_[v] = add(h_.vertex(v), values_.radiance(v), values_.gathered(v));
    return remap_[v];
  }

  // A foreign vertex is placed where the other patch has it, with this
  // polygon's own radiance there (interpolated along its edge from a to b):
  // the other patch may lie across a discontinuity (contact.h), whose light
  // must not bleed over.
  std::int32_t interpolated(std::uint32_t v, std::uint32_t a, std::uint32_t b) {
    const dvec3 p = h_.vertex(v), pa = h_.vertex(a), ab = h_.vertex(b) - pa;
    const double t = std::clamp(glm::dot(p - pa, ab) / glm::dot(ab, ab), 0.0, 1.0);
    return add(p, (1 - t) * values_.radiance(a) + t * values_.radiance(b),
               (1 - t) * values_.gathered(a) + t * values_.gathered(b));
  }

 private:
  std::int32_t add(const dvec3& solver_position, const glm::dvec3& radiance,
                   const glm::dvec3& gathered) {
    const auto index = static_cast<std::int32_t>(mesh_.positions.size() / 3);
    const dvec3 world = h_.scene().frame.to_world(solver_position);
    mesh_.positions.insert(mesh_.positions.end(), {world.x, world.y, world.z});
    append(mesh_.radiance, radiance);
    append(mesh_.vertex_irradiance, gathered);
    return index;
  }
  static void append(std::vector<float>& out, const glm::dvec3& value) {
    out.insert(out.end(), {static_cast<float>(value.x), static_cast<float>(value.y),
                           static_cast<float>(value.z)});
  }

  const Hierarchy& h_;
  const VertexValues& values_;
  OutputMesh& mesh_;
  std::vector<std::int32_t> remap_;
};

// The top-level element each element descends from.
std::vector<std::int32_t> roots_of(const std::vector<Element>& elements) {
  std::vector<std::int32_t> root_of(elements.size());
  for (size_t i = 0; i < elements.size(); ++i)  // parents come before children
    root_of[i] = elements[i].parent == kNone ? static_cast<std::int32_t>(i)
                                             : root_of[static_cast<size_t>(elements[i].parent)];
  return root_of;
}

}  // namespace

OutputMesh make_output_mesh(const Hierarchy& h,
                            const std::vector<std::array<Rgb, kMaxSamples>>& leaf_irradiance) {
  const auto& elements = h.elements();
  const std::vector<std::uint8_t> shown = shown_sides(h);
  const VertexValues values(h, leaf_irradiance, shown);
  OutputMesh mesh;
  OutputVertices vertices(h, values, mesh);
  const ForeignVertices foreign(h);
  const std::vector<std::int32_t> root_of = roots_of(elements);
  // One polygon per shown leaf: its corners, the vertices finer neighbours
  // made on its edges, and the foreign vertices there.
  std::vector<std::uint32_t> edge, between;
  for (size_t i = 0; i < elements.size(); ++i) {
    const Element& e = elements[i];
    if (!e.is_leaf() || !shown[2 * e.patch + e.side]) continue;
    const size_t polygon_start = mesh.face_vertices.size();
    for (int k = 0; k < e.corner_count; ++k) {
      const std::uint32_t a = e.corner[static_cast<size_t>(k)];
      const std::uint32_t b = e.corner[static_cast<size_t>((k + 1) % e.corner_count)];
      edge.clear();
      boundary_chain(h, a, b, edge);
      edge.push_back(b);
      for (size_t j = 0; j + 1 < edge.size(); ++j) {
        mesh.face_vertices.push_back(vertices.pool(edge[j]));
        between.clear();
        foreign.append_between(root_of[i], edge[j], edge[j + 1], between);
        for (std::uint32_t v : between)
          mesh.face_vertices.push_back(vertices.interpolated(v, edge[j], edge[j + 1]));
      }
    }
    mesh.face_sizes.push_back(static_cast<std::int32_t>(mesh.face_vertices.size() - polygon_start));
    mesh.source_face.push_back(static_cast<std::int32_t>(h.side_of(e).face));
    mesh.source_side.push_back(h.side_of(e).face_side);
    const Rgb mean = glm::max(h.average(e, leaf_irradiance[i]), Rgb(0.0));
    mesh.irradiance.insert(
        mesh.irradiance.end(),
        {static_cast<float>(mean.x), static_cast<float>(mean.y), static_cast<float>(mean.z)});
  }
  return mesh;
}

void require_finite(const OutputMesh& mesh) {
  const auto finite = [](const auto& values, size_t first, size_t count) {
    for (size_t i = first; i < first + count; ++i)
      if (!std::isfinite(values[i])) return false;
    return true;
  };
  size_t corner = 0;
  for (size_t p = 0; p < mesh.polygon_count(); ++p) {
    const char* what = finite(mesh.irradiance, 3 * p, 3) ? nullptr : "irradiance";
    const auto size = static_cast<size_t>(mesh.face_sizes[p]);
    for (size_t k = 0; k < size && !what; ++k) {
      const auto v = static_cast<size_t>(mesh.face_vertices[corner + k]);
      if (!finite(mesh.positions, 3 * v, 3))
        what = "position";
      else if (!finite(mesh.radiance, 3 * v, 3))
        what = "radiance";
      else if (!finite(mesh.vertex_irradiance, 3 * v, 3))
        what = "vertex irradiance";
    }
    corner += size;
    if (what) {
      throw std::runtime_error(std::string("the solve produced a non-finite ") + what +
                               " on input face " + std::to_string(mesh.source_face[p]) + " (" +
                               (mesh.source_side[p] ? "back" : "front") + " side, output polygon " +
                               std::to_string(p) +
                               "); this is a bug in the solver: nothing was written");
    }
  }
}

}  // namespace radiosity
