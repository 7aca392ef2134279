// Python access to occluded form factors (Section 4.3): visible_form_factor(),
// exact (visible polygon, exact gradient) or sampled (shadow rays through Embree),
// with the link's own faces left out as solve() leaves them out (shaft culling in
// exact mode, Embree's per-query ray filter in sampled mode).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/geometry/form_factor.h"
#include "core/geometry/triangle.h"
#include "core/solve/link_transport.h"
#include "core/visibility/ray_scene.h"
#include "core/visibility/sampled_visibility.h"
#include "core/visibility/visible_polygon.h"
#include "kernels/bindings.h"
#include "python/numpy_input.h"
#include "radiosity/solve.h"

namespace py = pybind11;

namespace radiosity::python {
namespace {

// The visible-polygon code needs a planar, convex emitter (the hierarchy's
// triangles and quads are): say so here rather than return a wrong number.
void require_planar_convex(const std::vector<dvec3>& polygon, const std::string& name) {
  if (const char* problem = planar_convex_problem(polygon))
    throw std::invalid_argument(name + " " + problem);
}

std::vector<Triangle> read_triangles(const py::handle& object, const std::string& name) {
  if (object.is_none()) return {};
  // An empty list or array (any shape with no elements) means no occluders.
  if (py::isinstance<py::sequence>(object) && !py::isinstance<py::str>(object) &&
      py::len(object) == 0)
    return {};
  const auto a = read_array(object, name, {-1, 3, 3});
  const auto m = static_cast<std::size_t>(a.shape(0));
  require_coordinates(a.data(), 9 * m, name);
  std::vector<Triangle> triangles(m);
  const double* p = a.data();
  for (std::size_t t = 0; t < m; ++t)
    for (int k = 0; k < 3; ++k)
      triangles[t].v[k] = {p[9 * t + 3 * k], p[9 * t + 3 * k + 1], p[9 * t + 3 * k + 2]};
  return triangles;
}

// The face of each occluder triangle: (m,) integers, or None for each its own.
std::vector<std::uint32_t> read_faces(const py::handle& object, std::size_t count) {
  std::vector<std::uint32_t> face(count);
  if (object.is_none()) {
    for (std::size_t t = 0; t < count; ++t) face[t] = static_cast<std::uint32_t>(t);
    return face;
  }
  const auto a = read_array_of<std::int64_t>(object, "faces", {static_cast<py::ssize_t>(count)});
  for (std::size_t t = 0; t < count; ++t) {
    const std::int64_t f = a.data()[t];
    if (f < 0 || f >= static_cast<std::int64_t>(kNoFace))
      throw std::invalid_argument("faces[" + std::to_string(t) + "] = " + std::to_string(f) +
                                  " is not a face id");
    face[t] = static_cast<std::uint32_t>(f);
  }
  return face;
}

// The link's own faces (receiver's, emitter's): at most two ids.
std::array<std::uint32_t, 2> read_own_faces(const py::handle& object) {
  std::array<std::uint32_t, 2> own{kNoFace, kNoFace};
  const auto a = read_array_of<std::int64_t>(object, "own_faces", {-1});
  if (a.size() > 2)
    throw std::invalid_argument("own_faces holds at most two faces (receiver's, emitter's)");
  for (py::ssize_t k = 0; k < a.size(); ++k) {
    if (a.data()[k] < 0 || a.data()[k] >= static_cast<std::int64_t>(kNoFace))
      throw std::invalid_argument("own_faces[" + std::to_string(k) + "] is not a face id");
    own[static_cast<std::size_t>(k)] = static_cast<std::uint32_t>(a.data()[k]);
  }
  return own;
}

// What both functions read: a receiver point and normal, a planar convex
// emitter and occluder triangles.
struct VisibilityInput {
  dvec3 point, normal;
  std::vector<dvec3> emitter;
  std::vector<Triangle> occluders;
};

VisibilityInput read_visibility_input(const py::handle& point, const py::handle& normal,
                                      const py::handle& emitter, const py::handle& occluders) {
  VisibilityInput in;
  in.point = read_point(point, "point");
  in.normal = read_unit_vec3(normal, "normal");
  in.emitter = read_polygon(emitter, "emitter");
  require_planar_convex(in.emitter, "emitter");
  in.occluders = read_triangles(occluders, "occluders");
  return in;
}

py::array_t<double> to_numpy(const std::vector<dvec3>& points) {
  py::array_t<double> out({static_cast<py::ssize_t>(points.size()), py::ssize_t{3}});
  auto w = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < points.size(); ++i)
    for (py::ssize_t k = 0; k < 3; ++k)
      w(static_cast<py::ssize_t>(i), k) = points[i][static_cast<int>(k)];
  return out;
}

}  // namespace

void bind_visibility(py::module_& m) {
  m.def(
      "visible_form_factor",
      [](const py::handle& point, const py::handle& normal, const py::handle& emitter,
         const py::handle& occluders, const std::string& mode, int rays, const py::handle& faces,
         const py::handle& own_faces) {
        const auto [r, n, polygon, triangles] =
            read_visibility_input(point, normal, emitter, occluders);
        const std::vector<std::uint32_t> face = read_faces(faces, triangles.size());
        const std::array<std::uint32_t, 2> own = read_own_faces(own_faces);
        const std::optional<VisibilityMode> visibility = parse_visibility(mode);
        if (!visibility)
          throw std::invalid_argument("mode must be 'exact' or 'sampled', got '" + mode + "'");
        if (rays < 1 || rays > kMaxRays)
          throw std::invalid_argument("rays must be in [1, " + std::to_string(kMaxRays) +
                                      "], got " + std::to_string(rays));
        FormFactorGradient result;
        {
          py::gil_scoped_release release;
          if (*visibility == VisibilityMode::Exact) {
            // As shaft culling does for a link: its own faces are no candidates.
            std::vector<Triangle> others;
            for (std::size_t t = 0; t < triangles.size(); ++t)
              if (face[t] != own[0] && face[t] != own[1]) others.push_back(triangles[t]);
            result = visible_form_factor_gradient(r, n, polygon, others);
          } else {
            // Every triangle goes to Embree, which must skip the own faces itself.
            const RayScene scene(triangles, face);
            SampledVisibilityOptions options;
            options.rays = rays;
            result = sampled_form_factor_gradient(r, n, polygon, scene, options, own[0], own[1]);
          }
        }
        return py::make_tuple(result.value, to_numpy(result.gradient));
      },
      py::arg("point"), py::arg("normal"), py::arg("emitter"), py::arg("occluders"),
      py::arg("mode") = "exact", py::arg("rays") = 64, py::arg("faces") = py::none(),
      py::arg("own_faces") = py::tuple(),
      "(F, grad F) of the part of `emitter` ((n, 3) convex planar polygon,\n"
      "counter-clockwise about its front normal) visible from `point` past\n"
      "`occluders` ((m, 3, 3) triangles, m may be 0).\n"
      "mode='exact': the visible polygon (Section 4.3) and its exact gradient.\n"
      "mode='sampled': `rays` stratified shadow rays (Embree) give the visible\n"
      "fraction; F and the unoccluded gradient are scaled by it.\n"
      "faces: (m,) the input face of each occluder (default: each its own);\n"
      "own_faces: up to two faces (the receiver's, the emitter's) that never shadow,\n"
      "as in solve(): left out in exact mode, skipped by Embree's ray filter in sampled mode.");
  m.def(
      "visible_polygon",
      [](const py::handle& point, const py::handle& normal, const py::handle& emitter,
         const py::handle& occluders) {
        const auto [r, n, polygon, triangles] =
            read_visibility_input(point, normal, emitter, occluders);
        VisiblePolygon visible;
        {
          py::gil_scoped_release release;
          visible = radiosity::visible_polygon(r, n, polygon, triangles);
        }
        py::list pieces;
        for (const VisiblePiece& piece : visible.pieces) {
          std::vector<dvec3> positions, anchors;
          py::list kinds;
          for (const ContourVertex& v : piece) {
            positions.push_back(v.position);
            anchors.push_back(v.anchor);
            kinds.append(v.apparent ? "apparent" : v.horizon ? "horizon" : "intrinsic");
          }
          py::dict d;
          d["positions"] = to_numpy(positions);
          d["anchors"] = to_numpy(anchors);
          d["kinds"] = kinds;
          pieces.append(d);
        }
        return py::make_tuple(pieces, visible.occluded);
      },
      py::arg("point"), py::arg("normal"), py::arg("emitter"), py::arg("occluders"),
      "The visible part of `emitter` from `point` (Section 4.3, Figure 19) as\n"
      "(pieces, occluded): convex pieces, each a dict with 'positions' (k, 3) on the\n"
      "emitter plane, 'anchors' (k, 3) (the 3D point an intrinsic vertex stands\n"
      "for: an occluder vertex, not its projection) and 'kinds' ('intrinsic',\n"
      "'apparent' or 'horizon'); `occluded` says whether an occluder mattered.");
}

}  // namespace radiosity::python
