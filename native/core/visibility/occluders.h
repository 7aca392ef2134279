// What blocks light in a scene, in the two forms visibility queries use: one
// or two triangles per occluding patch, tagged with the input face so a link
// never shadows itself.
#pragma once

#include <memory>

#include "core/visibility/ray_scene.h"
#include "core/visibility/shaft.h"
#include "radiosity/scene.h"

namespace radiosity {

struct SceneOccluders {
  OccluderScene shafts;
  std::unique_ptr<RayScene> rays;  // sampled visibility, cluster links
};

SceneOccluders make_scene_occluders(const Scene& scene);

}  // namespace radiosity
