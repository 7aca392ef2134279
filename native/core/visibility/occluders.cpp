#include "core/visibility/occluders.h"

#include <vector>

namespace radiosity {

SceneOccluders make_scene_occluders(const Scene& scene) {
  std::vector<Triangle> triangles;
  std::vector<std::uint32_t> face;
  for (const Patch& p : scene.occluders.empty() ? scene.patches : scene.occluders) {
    if (!p.occludes) continue;
    triangles.push_back({{p.corners[0], p.corners[1], p.corners[2]}});
    face.push_back(p.surface);
    if (p.corner_count == 4) {
      triangles.push_back({{p.corners[0], p.corners[2], p.corners[3]}});
      face.push_back(p.surface);
    }
  }
  SceneOccluders occluders;
  // Sampled visibility and cluster links cast rays.
  occluders.rays = std::make_unique<RayScene>(triangles, face);
  occluders.shafts = make_occluder_scene(std::move(triangles), std::move(face));
  return occluders;
}

}  // namespace radiosity
