// The scene the solver sees: input faces checked and turned into planar patches
// (quads kept when planar and convex, other polygons triangulated), each with
// its reflectance, emission and sidedness. Degenerate faces are skipped with a
// reason; broken but common ones (repeated corners, non-planar or
// self-crossing outlines) are repaired and listed; malformed input is
// rejected with a message naming the problem.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "radiosity/color.h"
#include "radiosity/lights.h"
#include "radiosity/vec.h"

namespace radiosity {

// The range of input the solver computes in: radiance (emission, lights, the
// world) up to kMaxInputRadiance, so that every bounce stays far inside the
// float32 output (3.4e38); coordinates within kMaxCoordinate; a scene at least
// kMinSceneSize across (a point light's I / d^2 over a micrometre scene
// already reaches 1e12 I) and at least kMinRelativeSize of its distance from
// the origin (the ray tracer works in float32). Other input is refused
// before any work (fuzzing found NaN and Inf beyond these limits).
inline constexpr double kMaxInputRadiance = 1e30;
inline constexpr double kMaxCoordinate = 1e30;
inline constexpr double kMinSceneSize = 1e-6;
inline constexpr double kMinRelativeSize = 1e-6;
// Faces smaller than kMinRelativeFaceSize of the scene's diameter, or than
// kMinFaceSizeOfReach of its distance from the origin, are skipped: their
// light is at most the square of that of the scene's, and at such sizes the
// sample offsets (hierarchy.h) vanish in rounding (a 3e-13 face in a 20 m
// room made NaN, fuzzing).
inline constexpr double kMinRelativeFaceSize = 1e-7;
inline constexpr double kMinFaceSizeOfReach = 1e-9;

// Views on the caller's arrays (numpy, without copies).
struct SceneArrays {
  std::span<const double> positions;            // 3 per vertex
  std::span<const std::int64_t> face_vertices;  // all faces' vertex indices, concatenated
  std::span<const std::int64_t> face_sizes;     // vertices per face
  std::span<const double> reflectance;          // 3 per face, in [0, 1]
  std::span<const double> emission;             // 3 per face, radiance >= 0
  std::span<const std::uint8_t> two_sided;      // per face, or empty: every face two-sided
  // Per face, or empty: every face casts shadows. Blender's lights do not
  // (Cycles lets light through them, measured): their polygons only emit.
  std::span<const std::uint8_t> occludes;
  // Point, spot and sun lights (lights.h), checked by make_scene.
  std::span<const Light> lights;
  // Radiance of a uniform world (Background colour x strength): light from
  // every direction a side sees past the scene's geometry.
  Rgb world{0.0};
};

// One side of a patch: the input face it shows and that face's material.
// Each side is its own radiosity surface; a side that is not present has no
// elements (the back of a one-sided face, or a side that coincides with
// another face's, contact.h).
struct PatchSide {
  bool present = false;
  std::uint32_t face = 0;      // index of the input face
  std::uint8_t face_side = 0;  // 0: that face's front, 1: its back
  Rgb reflectance{0.0};
  Rgb emission{0.0};
};

// Where the solver works: a scene's positions centred on its bounding box and
// scaled to a diameter of 1. Every tolerance of the solver, and the float32
// geometry of the ray tracer, is then the same for a scene modelled in
// millimetres or kilometres, at the origin or 10 km from it. Positions are
// then rounded to a grid of 2^-32 of the diameter (2.3 mm at 10,000 km, well
// under the smallest face kept, kMinRelativeFaceSize): the same scene in
// another unit or place differs by the last bits of its coordinates, which
// tipped refinement's decisions (up to 16 % more or fewer elements, 1.3e-3 of
// the light where point lights shine); on the grid it is the same numbers.
struct SolverFrame {
  static constexpr double kGrid = 4294967296.0;  // 2^32 steps per diameter
  dvec3 origin{0.0};
  double scale = 1.0;
  // Before rounding to the grid: what sizes under a grid step are judged by.
  dvec3 scaled(const dvec3& world) const { return (world - origin) * scale; }
  dvec3 to_solver(const dvec3& world) const { return glm::round(scaled(world) * kGrid) / kGrid; }
  dvec3 to_world(const dvec3& solver) const { return solver / scale + origin; }
};

// A planar, convex piece of surface: the top of the element hierarchy.
struct Patch {
  std::array<dvec3, 4> corners{};  // counter-clockwise about `normal`
  std::uint8_t corner_count = 0;   // 3 or 4
  dvec3 normal{0.0};               // front side
  double area = 0.0;
  // Patches of one surface never shadow each other: the input face (pieces
  // of a split face, the triangles of an n-gon), or for faces merged where
  // they coincide, the first of them.
  std::uint32_t surface = 0;
  bool occludes = true;              // casts shadows and takes part in contact meshing
  std::array<PatchSide, 2> sides{};  // front, back
  // Where contact.h cut the patch along the outline of something lying on it
  // or a line where something meets it, the radiance is discontinuous:
  // corners there are shared only with the patches of the same face on the
  // same side of it (class 0: no such line through the corner); samples on
  // an edge along the outline of a cover a gap g away move 4 g into the patch
  // (the cover's penumbra there is only about g wide), on a cut where a face
  // passes through it 1e-3 of its diameter (so they do not see that face
  // edge-on).
  std::array<std::uint32_t, 4> corner_class{};
  std::array<float, 4> edge_inset{};  // edge k runs from corner k to k + 1
};

// What was found wrong with an input face: why it was left out, or what was
// repaired before it was solved. Data, not words: the add-on words it.
enum class FaceIssue : std::uint8_t {
  CoincidentCorners,  // left out: zero area, its corners in one place
  CollinearCorners,   // left out: zero area, its corners on one line
  CrossesItself,      // left out: its outline crosses itself (it has no inside)
  TooSmall,           // left out: too small to solve in floating point (`size` across)
  NoTriangles,        // left out: nothing was left of it after triangulation
  RepeatedCorners,    // repaired: `count` repeated corners removed
  NotPlanar,          // repaired: bends by `bend`, split into `count` planar triangles
};
// "coincident_corners", "not_planar", ...: as the Python API names them.
std::string_view face_issue_name(FaceIssue issue);

struct FaceNote {
  std::uint32_t face;
  FaceIssue issue;
  std::uint32_t count = 0;  // RepeatedCorners: corners removed; NotPlanar: triangles made
  // TooSmall: the face's diameter and the scene's, in the input's units; NotPlanar: the corners'
  // largest distance from the face's plane as a fraction of its diameter.
  double size = 0.0;
  double scene_size = 0.0;
  double bend = 0.0;
};

// How many faces `notes` (in face order, as Scene lists them) concern.
std::size_t noted_faces(std::span<const FaceNote> notes);

// Every length, area and light in the solver's frame (`frame`).
struct Scene {
  SolverFrame frame;
  std::vector<Patch> patches;
  // What casts shadows: the faces' own planar pieces before contact.h split
  // them (a cut line must not be a crack light can slip through), without
  // those merged into a coinciding face.
  std::vector<Patch> occluders;
  std::vector<FaceNote> skipped;
  // Faces solved after a repair, one note per repair: repeated corners
  // removed, non-planar outlines split into triangles (with how far they bend).
  std::vector<FaceNote> repaired;
  // Direct light that is not a surface: the scene's lights, then the sky when
  // the world is not black (lights.h, direct_light.h).
  std::vector<Light> lights;
  // Pairs of input faces that coincide somewhere facing the same way (the
  // same surface twice, as z-fighting shows it); each is counted once
  // (contact.h). Coinciding faces that face each other (solids touching) are
  // merged alike but not listed.
  std::vector<std::array<std::uint32_t, 2>> coincident;
  std::size_t split_faces = 0;  // input faces split along what lies on or passes through them
  std::size_t face_count = 0;
  std::size_t vertex_count = 0;
  double total_area = 0.0;     // one side of every patch
  double emitted_power = 0.0;  // sum of luminance(L_e) x area over emitting sides
  double diameter = 0.0;       // of the scene's bounding box
  // Radiance the emitted power would give if spread over every surface: the
  // brightness scale that makes the oracles' thresholds relative (DESIGN s3).
  double reference_radiance() const { return emitted_power / total_area; }
};

// Validates and converts; throws std::invalid_argument with a clear message.
Scene make_scene(const SceneArrays& arrays);

}  // namespace radiosity
