// libFuzzer harness of scene validation (make_scene from SceneArrays, scene.h)
// and, for inputs that ask for it, a small solve of the scene (radiosity/solve.h):
// `make fuzz`. make_scene must turn any arrays into a scene or throw
// std::invalid_argument; solve() must return finite radiance and positions or
// throw std::invalid_argument. Findings: a sanitizer report, another
// exception, non-finite output, a hang (libFuzzer's -timeout).
//
// Input (sequential, fuzz_input.h): u8 flags (1: two_sided given, 2: occludes
// given, 4: solve, 8: sampled visibility, 16: two threads); u16 vertex count
// (at most 128) and 3 f64 per vertex; u16 face count (at most 32) and one i64
// size per face (raw: sizes may be negative or wrap around 2^64); u16 index
// count (at most 512) and one i64 per index (raw); 3 f64 reflectance and 3 f64
// emission per face; a u8 per face for two_sided and occludes when flagged;
// u8 light count (at most 4), each u8 kind (point, spot, sun) then colour,
// position, direction (3 f64 each), radius, angle, cos_half_angle, blend_width
// (f64) and u8 shape/falloff bits; world (3 f64); the solve's u8 oracle, f64
// quality, u16 max_elements, u8 bounces, f64 min_element_area, u8 leaf_links.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "fuzz/fuzz_input.h"
#include "radiosity/lights.h"
#include "radiosity/scene.h"
#include "radiosity/solve.h"

using namespace radiosity;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::Reader in(data, size);
  const std::uint8_t flags = in.u8();
  std::vector<double> positions(3 * in.count(128));
  for (double& v : positions) v = in.f64();
  std::vector<std::int64_t> face_sizes(in.count(32));
  for (std::int64_t& s : face_sizes) s = in.i64();
  std::vector<std::int64_t> face_vertices(in.count(512));
  for (std::int64_t& i : face_vertices) i = in.i64();
  const std::size_t faces = face_sizes.size();
  std::vector<double> reflectance(3 * faces), emission(3 * faces);
  for (double& v : reflectance) v = in.f64();
  for (double& v : emission) v = in.f64();
  std::vector<std::uint8_t> two_sided, occludes;
  if (flags & 1) {
    two_sided.resize(faces);
    for (auto& b : two_sided) b = in.u8() & 1;
  }
  if (flags & 2) {
    occludes.resize(faces);
    for (auto& b : occludes) b = in.u8() & 1;
  }
  std::vector<Light> lights(in.u8() % 5);
  for (Light& light : lights) {
    light.kind = static_cast<LightKind>(in.u8() % 3);  // point, spot, sun (the sky is the world)
    light.colour = Rgb(in.vec3());
    light.position = in.vec3();
    light.direction = in.vec3();
    light.radius = in.f64();
    light.angle = in.f64();
    light.cos_half_angle = in.f64();
    light.blend_width = in.f64();
    const std::uint8_t bits = in.u8();
    light.sphere = bits & 1;
    light.cosine_falloff = bits & 2;
  }
  const dvec3 world = in.vec3();

  SceneArrays arrays;
  arrays.positions = positions;
  arrays.face_vertices = face_vertices;
  arrays.face_sizes = face_sizes;
  arrays.reflectance = reflectance;
  arrays.emission = emission;
  arrays.two_sided = two_sided;
  arrays.occludes = occludes;
  arrays.lights = lights;
  arrays.world = Rgb(world);
  Scene scene;
  try {
    scene = make_scene(arrays);
  } catch (const std::invalid_argument&) {
    return 0;  // a clean refusal
  }
  for (const Patch& p : scene.patches) {
    for (int k = 0; k < p.corner_count; ++k)
      fuzz::require_finite(p.corners[static_cast<std::size_t>(k)], "patch corner");
    fuzz::require_finite(p.normal, "patch normal");
    fuzz::require_finite(p.area, "patch area");
  }
  if (!(flags & 4)) return 0;

  SolveOptions options;
  options.oracle = static_cast<Oracle>(in.u8() % 3);
  options.quality = std::abs(std::fmod(in.f64(), 1.0));
  if (!std::isfinite(options.quality)) options.quality = 0.0;
  options.max_elements = 1 + in.u16() % 256;
  options.bounces = 1 + in.u8() % 4;
  const double area = std::abs(in.f64());
  options.min_element_area = std::isfinite(area) && area > 1e-4 && area < 1.0 ? area : 1e-2;
  options.leaf_links = static_cast<SolveOptions::LeafLinks>(in.u8() % 3);
  options.visibility = (flags & 8) ? VisibilityMode::Sampled : VisibilityMode::Exact;
  options.rays = 4;
  options.threads = (flags & 16) ? 2 : 1;
  options.time_budget = 2.0;
  SolveResult result;
  try {
    result = solve(scene, options);
  } catch (const std::invalid_argument&) {
    return 0;
  }
  const OutputMesh& m = result.mesh;
  for (double v : m.positions) fuzz::require_finite(v, "output position");
  for (float v : m.radiance) fuzz::require_finite(v, "output radiance");
  for (float v : m.vertex_irradiance) fuzz::require_finite(v, "output vertex_irradiance");
  for (float v : m.irradiance) fuzz::require_finite(v, "output irradiance");
  return 0;
}
