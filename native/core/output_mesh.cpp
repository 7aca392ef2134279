#include "core/output_mesh.h"

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

}  // namespace

OutputMesh make_output_mesh(const Hierarchy& h,
                            const std::vector<std::array<Rgb, kMaxSamples>>& leaf_irradiance) {
  const auto& elements = h.elements();
  const Scene& scene = h.scene();

  // A side is shown when light reaches it or it emits (the back of a two-sided
  // lamp seen from above); a face that no light reaches shows its front, dark,
  // so the geometry stays whole.
  std::vector<std::uint8_t> lit(2 * scene.patches.size(), 0);
  for (const Element& e : elements) lit[2 * e.patch + e.side] |= e.has_links;
  const auto shown = [&](std::uint32_t patch, int side) {
    if (h.root(patch, side) == kNone) return false;
    if (lit[2 * patch + static_cast<size_t>(side)]) return true;
    if (luminance(scene.patches[patch].emission) > 0.0) return true;
    return side == 0 && !lit[2 * patch + 1];
  };

  // Radiance at pool vertices: the mean over the leaves that have it as a corner.
  std::vector<glm::dvec3> sum(h.vertex_count(), glm::dvec3(0.0));
  std::vector<std::uint32_t> count(h.vertex_count(), 0);
  for (size_t i = 0; i < elements.size(); ++i) {
    const Element& e = elements[i];
    if (!e.is_leaf() || !shown(e.patch, e.side)) continue;
    const Rgb rho = h.reflectance(e), emission = h.emission(e);
    for (int k = 0; k < e.corner_count; ++k) {
      // Energy-conserving link corrections (link_transport.cpp) may leave a
      // sample a rounding below zero; light is never negative.
      const Rgb value = emission + rho * glm::max(leaf_irradiance[i][static_cast<size_t>(k)], Rgb(0.0));
      sum[e.corner[static_cast<size_t>(k)]] += glm::dvec3(value);
      ++count[e.corner[static_cast<size_t>(k)]];
    }
  }

  OutputMesh mesh;
  std::vector<std::int32_t> remap(h.vertex_count(), kNone);
  const auto output_vertex = [&](std::uint32_t v) {
    if (remap[v] == kNone) {
      remap[v] = static_cast<std::int32_t>(mesh.positions.size() / 3);
      const dvec3& p = h.vertex(v);
      mesh.positions.insert(mesh.positions.end(), {p.x, p.y, p.z});
      const glm::dvec3 value = count[v] ? sum[v] / static_cast<double>(count[v]) : glm::dvec3(0.0);
      mesh.radiance.insert(mesh.radiance.end(), {static_cast<float>(value.x),
                                                 static_cast<float>(value.y),
                                                 static_cast<float>(value.z)});
    }
    return remap[v];
  };
  std::vector<std::uint32_t> polygon;
  for (size_t i = 0; i < elements.size(); ++i) {
    const Element& e = elements[i];
    if (!e.is_leaf() || !shown(e.patch, e.side)) continue;
    polygon.clear();
    for (int k = 0; k < e.corner_count; ++k) {
      const std::uint32_t a = e.corner[static_cast<size_t>(k)];
      const std::uint32_t b = e.corner[static_cast<size_t>((k + 1) % e.corner_count)];
      polygon.push_back(a);
      append_hanging(h, a, b, polygon);
    }
    for (std::uint32_t v : polygon) mesh.face_vertices.push_back(output_vertex(v));
    mesh.face_sizes.push_back(static_cast<std::int32_t>(polygon.size()));
    mesh.source_face.push_back(static_cast<std::int32_t>(h.patch_of(e).face));
    mesh.source_side.push_back(e.side);
    const Rgb mean = glm::max(Interpolant::average(e.corner_count, leaf_irradiance[i]), Rgb(0.0));
    mesh.irradiance.insert(mesh.irradiance.end(), {static_cast<float>(mean.x),
                                                   static_cast<float>(mean.y),
                                                   static_cast<float>(mean.z)});
  }
  return mesh;
}

}  // namespace radiosity
