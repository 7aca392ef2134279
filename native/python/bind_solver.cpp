// Python access to the solver: Scene, solve(), Result and CancelToken.
// numpy in (validated, no copies of the caller's arrays), numpy out (the
// result's vectors are handed over, not copied); the GIL is released while
// solving, and the progress callback re-acquires it.
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <atomic>
#include <exception>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "core/solve/system_memory.h"
#include "python/bindings.h"
#include "python/numpy_input.h"
#include "radiosity/scene.h"
#include "radiosity/solve.h"

namespace py = pybind11;

namespace radiosity::python {
namespace {

struct CancelToken {
  std::atomic<bool> flag{false};
};

// A SolveReuse, the lock that keeps two solves from using it at once, and
// what it holds as of its last solve or clear: read from Python (a panel's
// draw) while a solve on another thread may be replacing it.
struct PyReuse {
  SolveReuse reuse;
  std::mutex mutex;
  std::atomic<bool> holds{false};
  std::atomic<std::size_t> bytes{0};
  void note() {  // with `mutex` held
    holds = reuse.holds();
    bytes = reuse.memory_bytes();
  }
};

// What a solve running on another thread has reported, for a caller that polls
// it (Blender's UI timer). The solver thread only copies under a mutex and
// never waits for Python's GIL, so a busy interface cannot slow the solve (a
// callback waits for the GIL at every report) and the solve cannot stall it.
struct ProgressMonitor {
  std::mutex mutex;
  std::optional<SolveProgress> latest;     // its pass_result cleared
  std::optional<SolveResult> pass_result;  // the newest pass's solution, until taken
  bool keep_pass_results = false;

  void record(const SolveProgress& p) {
    std::optional<SolveResult> copy;
    if (keep_pass_results && p.pass_result) copy = *p.pass_result;  // outside the lock
    const std::lock_guard<std::mutex> lock(mutex);
    latest = p;
    latest->pass_result = nullptr;
    if (copy) pass_result = std::move(copy);
  }
};

// Integer input must hold integers: a float array is accepted only if whole.
InputArray<std::int64_t> read_indices(const py::handle& object, const std::string& name) {
  if (!object.is_none()) {
    const auto as_array = py::array::ensure(object);
    if (as_array && as_array.dtype().kind() == 'f') {
      const auto floats = read_array_of<double>(object, name, {-1});
      for (py::ssize_t i = 0; i < floats.size(); ++i) {
        const double v = floats.data()[i];
        if (!std::isfinite(v) || v != std::floor(v)) {
          throw std::invalid_argument(name + " must hold integers (index " + std::to_string(i) +
                                      ")");
        }
      }
    }
  }
  return read_array_of<std::int64_t>(object, name, {-1});
}

dvec3 read_vector(const py::dict& light, const char* key, const std::string& which) {
  const auto v = read_array_of<double>(light[key], which + key, {3});
  return {v.data()[0], v.data()[1], v.data()[2]};
}

double read_number(const py::dict& light, const char* key, const std::string& which) {
  try {
    return light[key].cast<double>();
  } catch (const py::cast_error&) {
    throw std::invalid_argument(which + key + " must be a number");
  }
}

// One light from a dict: type 'point' | 'spot' | 'sun' and its parameters
// (lights.h); unknown keys are refused, so a misspelt one is not ignored.
Light read_light(const py::handle& item, size_t index) {
  const std::string which = "lights[" + std::to_string(index) + "].";
  if (!py::isinstance<py::dict>(item))
    throw std::invalid_argument("lights[" + std::to_string(index) + "] must be a dict");
  const auto light = py::reinterpret_borrow<py::dict>(item);
  if (!light.contains("type"))
    throw std::invalid_argument(which + "type is missing ('point', 'spot' or 'sun')");
  const auto kind = parse_light_kind(py::str(light["type"]).cast<std::string>());
  if (!kind) throw std::invalid_argument(which + "type must be 'point', 'spot' or 'sun'");
  Light out;
  out.kind = *kind;
  std::vector<std::string> allowed = {"type"};
  const auto take = [&](const char* key, bool required) {
    allowed.emplace_back(key);
    if (light.contains(key)) return true;
    if (required) throw std::invalid_argument(which + key + " is missing");
    return false;
  };
  if (out.kind == LightKind::Sun) {
    take("irradiance", true);
    const dvec3 e = read_vector(light, "irradiance", which);
    out.colour = Rgb(e);
    take("direction", true);
    out.direction = read_vector(light, "direction", which);
    if (take("angle", false)) out.angle = read_number(light, "angle", which);
  } else {
    take("intensity", true);
    out.colour = Rgb(read_vector(light, "intensity", which));
    take("position", true);
    out.position = read_vector(light, "position", which);
    if (take("radius", false)) out.radius = read_number(light, "radius", which);
    if (take("shape", false)) {
      const std::string shape = py::str(light["shape"]).cast<std::string>();
      if (shape != "sphere" && shape != "disk")
        throw std::invalid_argument(which + "shape must be 'sphere' or 'disk'");
      out.sphere = shape == "sphere";
    }
    if (out.kind == LightKind::Spot) {
      take("direction", true);
      out.direction = read_vector(light, "direction", which);
      take("cos_half_angle", true);
      out.cos_half_angle = read_number(light, "cos_half_angle", which);
      if (take("blend_width", false)) out.blend_width = read_number(light, "blend_width", which);
      if (take("cosine_falloff", false)) out.cosine_falloff = light["cosine_falloff"].cast<bool>();
    }
  }
  for (const auto& [key, value] : light) {
    const std::string name = py::str(key).cast<std::string>();
    if (std::find(allowed.begin(), allowed.end(), name) == allowed.end())
      throw std::invalid_argument(which + name + " is not a setting of a " +
                                  py::str(light["type"]).cast<std::string>() + " light");
  }
  return out;
}

Scene make_python_scene(const py::handle& positions, const py::handle& face_vertices,
                        const py::handle& face_sizes, const py::handle& reflectance,
                        const py::handle& emission, const py::handle& two_sided,
                        const py::handle& occludes, const py::handle& lights,
                        const py::handle& world) {
  const auto p = read_array_of<double>(positions, "positions", {-1, 3});
  const auto fv = read_indices(face_vertices, "face_vertices");
  const auto fs = read_indices(face_sizes, "face_sizes");
  const auto faces = fs.shape(0);
  const auto rho = read_array_of<double>(reflectance, "reflectance", {faces, 3});
  const auto le = read_array_of<double>(emission, "emission", {faces, 3});
  InputArray<std::uint8_t> sided;
  if (!two_sided.is_none()) sided = read_array_of<std::uint8_t>(two_sided, "two_sided", {faces});
  InputArray<std::uint8_t> shadows;
  if (!occludes.is_none()) shadows = read_array_of<std::uint8_t>(occludes, "occludes", {faces});
  SceneArrays arrays;
  arrays.positions = {p.data(), static_cast<size_t>(p.size())};
  arrays.face_vertices = {fv.data(), static_cast<size_t>(fv.size())};
  arrays.face_sizes = {fs.data(), static_cast<size_t>(fs.size())};
  arrays.reflectance = {rho.data(), static_cast<size_t>(rho.size())};
  arrays.emission = {le.data(), static_cast<size_t>(le.size())};
  if (sided) arrays.two_sided = {sided.data(), static_cast<size_t>(sided.size())};
  if (shadows) arrays.occludes = {shadows.data(), static_cast<size_t>(shadows.size())};
  std::vector<Light> light_list;
  if (!lights.is_none()) {
    if (!py::isinstance<py::sequence>(lights) || py::isinstance<py::str>(lights))
      throw std::invalid_argument("lights must be a list of dicts");
    size_t index = 0;
    for (const py::handle item : lights) light_list.push_back(read_light(item, index++));
  }
  arrays.lights = light_list;
  if (!world.is_none()) {
    const auto w = read_array_of<double>(world, "world", {3});
    arrays.world = Rgb(w.data()[0], w.data()[1], w.data()[2]);
  }
  return make_scene(arrays);
}

// Hands a vector to numpy without copying: the array owns it through a capsule.
template <class T>
py::array_t<T> hand_over(std::vector<T>&& v, std::vector<py::ssize_t> shape) {
  auto* owner = new std::vector<T>(std::move(v));
  py::capsule free_when_done(owner, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>(shape, owner->data(), free_when_done);
}

struct PyResult {
  py::array_t<double> positions;
  py::array_t<std::int32_t> face_vertices, face_sizes, source_face;
  py::array_t<float> radiance, vertex_irradiance;
  py::array_t<std::uint8_t> source_side;
  py::array_t<float> irradiance;
  py::dict stats;
};

// Scene::skipped or repaired as Python data: the kind by name, and the
// numbers that kind has.
py::list face_notes(const std::vector<FaceNote>& notes) {
  py::list out;
  for (const FaceNote& n : notes) {
    py::dict d;
    d["face"] = n.face;
    d["kind"] = std::string(face_issue_name(n.issue));
    if (n.issue == FaceIssue::TooSmall) {
      d["size"] = n.size;
      d["scene_size"] = n.scene_size;
    } else if (n.issue == FaceIssue::RepeatedCorners) {
      d["corners"] = n.count;
    } else if (n.issue == FaceIssue::NotPlanar) {
      d["bend"] = n.bend;
      d["triangles"] = n.count;
    }
    out.append(std::move(d));
  }
  return out;
}

py::dict stats_dict(const SolveStats& s) {
  py::dict d;
  d["elements"] = s.elements;
  d["leaves"] = s.leaves;
  d["links"] = s.links;
  d["cluster_links"] = s.cluster_links;
  d["light_links"] = s.light_links;
  d["passes"] = s.passes;
  d["iterations"] = s.iterations;
  d["residual"] = s.residual;
  d["threshold"] = s.threshold;
  d["skipped_faces"] = s.skipped_faces;
  d["repaired_faces"] = s.repaired_faces;
  d["cancelled"] = s.cancelled;
  d["reused"] = s.reused;
  d["reuse_refusal"] = std::string(relight_refusal_name(s.reuse_refusal));
  d["stopped_by"] = std::string(stop_reason_name(s.stopped_by));
  d["seconds"] = s.seconds;
  d["seconds_linking"] = s.seconds_linking;
  d["seconds_clustering"] = s.seconds_clustering;
  d["seconds_ray_pass"] = s.seconds_ray_pass;
  d["ray_pass_rays"] = s.ray_pass_rays;
  d["unlit_sides"] = s.unlit_sides;
  d["dim_sides"] = s.dim_sides;
  d["seconds_gather"] = s.seconds_gather;
  d["cpu_visibility"] = s.link_cpu.visibility;
  d["cpu_form_factors"] = s.link_cpu.form_factors;
  d["cpu_oracle"] = s.link_cpu.oracle;
  d["samples_clear"] = s.link_cpu.samples_clear;
  d["samples_occluded"] = s.link_cpu.samples_occluded;
  d["samples_faint"] = s.link_cpu.samples_faint;
  d["samples_shared"] = s.link_cpu.samples_shared;
  d["grid_points_faint"] = s.link_cpu.grid_points_faint;
  d["element_bytes"] = s.element_bytes;
  d["link_bytes"] = s.link_bytes;
  d["peak_bytes"] = s.peak_bytes;
  d["bytes_per_element"] =
      s.elements ? static_cast<double>(s.element_bytes) / static_cast<double>(s.elements) : 0.0;
  const std::size_t all_links = s.links + s.cluster_links;
  d["bytes_per_link"] =
      all_links ? static_cast<double>(s.link_bytes) / static_cast<double>(all_links) : 0.0;
  d["peak_rss_bytes"] = peak_resident_bytes();
  return d;
}

PyResult to_python(SolveResult&& r) {
  PyResult out;
  OutputMesh& m = r.mesh;
  const auto vertices = static_cast<py::ssize_t>(m.vertex_count());
  const auto polygons = static_cast<py::ssize_t>(m.polygon_count());
  const auto corners = static_cast<py::ssize_t>(m.face_vertices.size());
  out.positions = hand_over(std::move(m.positions), {vertices, 3});
  out.radiance = hand_over(std::move(m.radiance), {vertices, 3});
  out.vertex_irradiance = hand_over(std::move(m.vertex_irradiance), {vertices, 3});
  out.face_vertices = hand_over(std::move(m.face_vertices), {corners});
  out.face_sizes = hand_over(std::move(m.face_sizes), {polygons});
  out.source_face = hand_over(std::move(m.source_face), {polygons});
  out.source_side = hand_over(std::move(m.source_side), {polygons});
  out.irradiance = hand_over(std::move(m.irradiance), {polygons, 3});
  out.stats = stats_dict(r.stats);
  return out;
}

py::dict progress_dict(const SolveProgress& p) {
  py::dict d;
  d["pass"] = p.pass;
  d["passes"] = p.passes;
  d["phase"] = std::string(phase_name(p.phase));
  d["elements"] = p.elements;
  d["leaves"] = p.leaves;
  d["links"] = p.links;
  d["threshold"] = p.threshold;
  d["seconds"] = p.seconds;
  d["fraction"] = p.fraction;
  return d;
}

// The oracles' names quoted and joined: "'a', 'b' or 'c'" (`last` "or"), or
// "'a' | 'b' | 'c'" (`between` and `last` " | ").
std::string oracle_choices(std::string_view between, std::string_view last) {
  std::string out;
  for (size_t i = 0; i < kOracles.size(); ++i) {
    if (i) out.append(i + 1 == kOracles.size() ? last : between);
    out.append("'").append(oracle_name(kOracles[i])).append("'");
  }
  return out;
}

Oracle read_oracle(const std::string& name) {
  const auto oracle = parse_oracle(name);
  if (!oracle) {
    throw std::invalid_argument("oracle must be " + oracle_choices(", ", " or ") + ", got '" +
                                name + "'");
  }
  return *oracle;
}

VisibilityMode read_visibility(const std::string& name, const char* what) {
  const auto mode = parse_visibility(name);
  if (!mode)
    throw std::invalid_argument(std::string(what) + " must be 'exact' or 'sampled', got '" + name +
                                "'");
  return *mode;
}

// Python's integers are unbounded: a count is range-checked here, so that any
// int gives ValueError, never a TypeError or a wrapped value.
int read_count(const py::object& value, const char* name, std::int64_t lo, std::int64_t hi) {
  const std::string range = std::string(name) + " must be an integer in [" + std::to_string(lo) +
                            ", " + std::to_string(hi) + "]";
  // Anything with __index__ (int, numpy integers); not floats.
  const auto index = py::reinterpret_steal<py::object>(PyNumber_Index(value.ptr()));
  if (!index) {
    PyErr_Clear();
    throw std::invalid_argument(range + ", got " + py::repr(value).cast<std::string>());
  }
  const auto within = [&](std::int64_t bound, int op) {
    const py::int_ b(bound);
    return PyObject_RichCompareBool(index.ptr(), b.ptr(), op) == 1;
  };
  if (!within(lo, Py_GE) || !within(hi, Py_LE))
    throw std::invalid_argument(range + ", got " + py::repr(value).cast<std::string>());
  return static_cast<int>(index.cast<std::int64_t>());
}

// The options of solve() but for its callbacks, checked.
SolveOptions read_options(const std::string& oracle, double quality, const py::object& max_elements,
                          std::optional<double> time_budget, const std::string& visibility,
                          const py::object& rays, const py::object& bounces,
                          const py::object& threads, double min_element_area,
                          const std::string& leaf_links, std::optional<double> cluster_separation,
                          double dim_share, double faint_share, const py::object& memory_limit,
                          bool yield_to_interface) {
  SolveOptions options;
  options.oracle = read_oracle(oracle);
  options.quality = quality;
  constexpr std::int64_t kMaxCount = std::int64_t{1} << 62;
  if (!max_elements.is_none()) {
    options.max_elements =
        static_cast<std::size_t>(read_count(max_elements, "max_elements", 1, INT32_MAX));
  }
  options.time_budget = time_budget;
  options.visibility = read_visibility(visibility, "visibility");
  options.rays = read_count(rays, "rays", 1, kMaxRays);
  if (!bounces.is_none()) options.bounces = read_count(bounces, "bounces", 1, INT32_MAX);
  if (!threads.is_none()) options.threads = read_count(threads, "threads", 1, kMaxThreads);
  if (!memory_limit.is_none()) {
    const auto v = py::cast<double>(py::float_(memory_limit));
    if (!(v >= 1.0 && v <= static_cast<double>(kMaxCount)))
      throw std::invalid_argument("memory_limit must be a positive number of bytes");
    options.memory_limit = static_cast<std::size_t>(v);
  }
  options.min_element_area = min_element_area;
  options.yield_to_interface = yield_to_interface;
  if (cluster_separation) {
    if (!(*cluster_separation > 1.0))
      throw std::invalid_argument(
          "cluster_separation must be greater than 1 (or inf: no cluster links)");
    options.cluster_separation = *cluster_separation;
  }
  if (!(dim_share >= 0.0 && dim_share <= 1.0))
    throw std::invalid_argument("dim_share must lie in [0, 1] (0: every lit side is linked)");
  options.dim_share = dim_share;
  if (!(faint_share >= 0.0 && faint_share <= 1.0))
    throw std::invalid_argument("faint_share must lie in [0, 1] (0: every sample exact)");
  options.faint_share = faint_share;
  const auto links = parse_leaf_links(leaf_links);
  if (!links)
    throw std::invalid_argument("leaf_links must be 'none', 'near' or 'all', got '" + leaf_links +
                                "'");
  options.leaf_links = *links;
  return options;
}

// The first exception of a Python callback or clock the solve's threads
// called: it stops the solve and is raised afterwards.
struct CallbackError {
  std::exception_ptr error;
  std::atomic<bool> failed{false};
  void keep(std::exception_ptr e) {  // with the GIL held
    error = std::move(e);
    failed = true;
  }
};

// solve(progress=...) as the solver calls it: a ProgressMonitor's record, or
// the Python callable called with the GIL (both alive while the solve runs).
ProgressCallback progress_callback(const py::object& progress, bool pass_results,
                                   CallbackError& failure) {
  if (py::isinstance<ProgressMonitor>(progress)) {
    ProgressMonitor* monitor = progress.cast<ProgressMonitor*>();
    monitor->keep_pass_results = monitor->keep_pass_results || pass_results;
    return [monitor](const SolveProgress& p) { monitor->record(p); };
  }
  if (progress.is_none()) return {};
  if (!PyCallable_Check(progress.ptr()))
    throw std::invalid_argument("progress must be callable, a ProgressMonitor or None");
  return [&progress, pass_results, &failure](const SolveProgress& p) {
    py::gil_scoped_acquire gil;
    if (failure.error) return;
    try {
      py::dict d = progress_dict(p);
      // A copy: the solver goes on refining the hierarchy this mesh came from.
      if (pass_results && p.pass_result) d["result"] = to_python(SolveResult(*p.pass_result));
      progress(d);
    } catch (...) {
      failure.keep(std::current_exception());
    }
  };
}

// solve(clock=...) as the solver reads it, from the solve's threads; a
// failing clock stops the solve like a failing callback (its time then reads
// as past any budget).
std::function<double()> python_clock(const py::object& clock, CallbackError& failure) {
  if (clock.is_none()) return {};
  if (!PyCallable_Check(clock.ptr())) throw std::invalid_argument("clock must be callable or None");
  return [&clock, &failure]() -> double {
    py::gil_scoped_acquire gil;
    if (!failure.error) {
      try {
        return py::cast<double>(clock());
      } catch (...) {
        failure.keep(std::current_exception());
      }
    }
    return std::numeric_limits<double>::infinity();
  };
}

// solve() without the GIL, with `kept` locked for it if given.
SolveResult solve_released(const Scene& scene, const SolveOptions& options,
                           const ProgressCallback& callback, const CancelCheck& cancelled,
                           PyReuse* kept) {
  // Taken before the GIL goes: a second solve with the same reuse fails at once.
  std::unique_lock<std::mutex> in_use;
  if (kept) {
    in_use = std::unique_lock<std::mutex>(kept->mutex, std::try_to_lock);
    if (!in_use.owns_lock())
      throw std::invalid_argument("this SolveReuse is in use by another solve");
  }
  SolveResult result;
  {
    py::gil_scoped_release release;
    try {
      result = solve(scene, options, callback, cancelled, kept ? &kept->reuse : nullptr);
    } catch (...) {
      if (kept) kept->note();
      throw;
    }
  }
  if (kept) kept->note();
  return result;
}

PyResult py_solve(const Scene& scene, const std::string& oracle, double quality,
                  const py::object& max_elements, std::optional<double> time_budget,
                  const std::string& visibility, const py::object& rays, const py::object& bounces,
                  const py::object& threads, const py::object& progress, const py::object& cancel,
                  double min_element_area, const std::string& leaf_links,
                  std::optional<double> cluster_separation, double dim_share, double faint_share,
                  const py::object& memory_limit, bool pass_results, bool yield_to_interface,
                  const py::object& reuse, const py::object& clock) {
  SolveOptions options =
      read_options(oracle, quality, max_elements, time_budget, visibility, rays, bounces, threads,
                   min_element_area, leaf_links, cluster_separation, dim_share, faint_share,
                   memory_limit, yield_to_interface);
  PyReuse* kept = nullptr;
  if (!reuse.is_none()) {
    if (!py::isinstance<PyReuse>(reuse))
      throw std::invalid_argument("reuse must be a SolveReuse or None");
    kept = reuse.cast<PyReuse*>();
  }
  const CancelToken* token = nullptr;
  if (!cancel.is_none()) {
    if (!py::isinstance<CancelToken>(cancel))
      throw std::invalid_argument("cancel must be a CancelToken or None");
    token = cancel.cast<CancelToken*>();
  }
  CallbackError failure;
  const ProgressCallback callback = progress_callback(progress, pass_results, failure);
  options.clock = python_clock(clock, failure);
  const CancelCheck cancelled = [&] {
    return failure.failed.load() || (token && token->flag.load());
  };
  SolveResult result = solve_released(scene, options, callback, cancelled, kept);
  if (failure.error) std::rethrow_exception(failure.error);
  return to_python(std::move(result));
}

}  // namespace

void bind_solver(py::module_& m) {
  py::register_exception<InsufficientMemory>(m, "InsufficientMemoryError", PyExc_MemoryError);
  // The options' defaults and limits by name, as JSON (the add-on's solver_defaults.json).
  // As text: importing Python's json here would load a library from the machine
  // (tests/native/test_package.py holds the module to its own).
  m.attr("DEFAULTS_JSON") = defaults_json();
  py::class_<CancelToken>(
      m, "CancelToken",
      "A flag another thread can set to stop a solve; the solve then returns the "
      "last complete pass.")
      .def(py::init<>())
      .def(
          "cancel", [](CancelToken& t) { t.flag = true; }, "Ask the solve to stop.")
      .def_property_readonly("cancelled", [](const CancelToken& t) { return t.flag.load(); });

  py::class_<PyReuse>(
      m, "SolveReuse",
      "Keeps the elements and links of the last complete solve it was passed to\n"
      "(solve(reuse=...)), so that the next solve of the same geometry with the same options\n"
      "relights it (stats['reused']) when only emission, reflectance or the lights' colours\n"
      "and strengths changed; otherwise that solve starts from nothing and is kept instead.")
      .def(py::init<>())
      .def_property_readonly(
          "holds", [](PyReuse& r) { return r.holds.load(); },
          "whether a solve is kept (as of the last solve with it)")
      .def_property_readonly(
          "memory_bytes", [](PyReuse& r) { return r.bytes.load(); },
          "bytes the kept solve holds (as of the last solve with it)")
      .def(
          "clear",
          [](PyReuse& r) {
            std::unique_lock<std::mutex> in_use(r.mutex, std::try_to_lock);
            if (!in_use.owns_lock())
              throw std::invalid_argument("this SolveReuse is in use by a solve");
            r.reuse.clear();
            r.note();
          },
          "Free the kept solve.");

  py::class_<ProgressMonitor>(
      m, "ProgressMonitor",
      "ProgressMonitor(pass_results=False): pass it as solve(progress=...) and poll it from\n"
      "another thread; the solve never waits for Python to report. progress() is the latest\n"
      "report (as a progress callback gets it) or None; take_pass_result() the newest pass's\n"
      "solution not taken yet, or None (with pass_results).")
      .def(py::init([](bool pass_results) {
             auto monitor = std::make_unique<ProgressMonitor>();
             monitor->keep_pass_results = pass_results;
             return monitor;
           }),
           py::arg("pass_results") = false)
      .def("progress",
           [](ProgressMonitor& monitor) -> py::object {
             std::optional<SolveProgress> latest;
             {
               const std::lock_guard<std::mutex> lock(monitor.mutex);
               latest = monitor.latest;
             }
             if (!latest) return py::none();
             return progress_dict(*latest);
           })
      .def("take_pass_result", [](ProgressMonitor& monitor) -> py::object {
        std::optional<SolveResult> taken;
        {
          const std::lock_guard<std::mutex> lock(monitor.mutex);
          taken.swap(monitor.pass_result);
        }
        if (!taken) return py::none();
        return py::cast(to_python(std::move(*taken)));
      });

  py::class_<Scene>(
      m, "Scene",
      "Scene(positions, face_vertices, face_sizes, reflectance, emission, two_sided=None, "
      "occludes=None,\n"
      "      lights=None, world=None)\n\n"
      "positions (V, 3) float; face_vertices: all faces' vertex indices concatenated;\n"
      "face_sizes (F,) vertices per face (3 or more; larger polygons are triangulated);\n"
      "reflectance (F, 3) in [0, 1]; emission (F, 3) radiance >= 0; two_sided (F,) bool,\n"
      "default all True (a one-sided face has only its front: area lights); occludes (F,) bool,\n"
      "default all True (False: the face emits but casts no shadow and must not reflect, as "
      "Blender's lights).\n"
      "lights: list of dicts, each {'type': 'point', 'position', 'intensity' (H = I cos / d^2),\n"
      "'radius', 'shape': 'sphere' | 'disk'}, {'type': 'spot', the same and 'direction' (its "
      "axis),\n"
      "'cos_half_angle', 'blend_width', 'cosine_falloff'} or {'type': 'sun', 'direction' (the way\n"
      "its light travels), 'irradiance' (H facing it), 'angle' (radians)}; world (3,): the "
      "radiance of\n"
      "a uniform world, light from every direction that leaves the scene.\n"
      "Degenerate faces are skipped (skipped_faces), broken ones repaired (repaired_faces); bad "
      "input\n"
      "raises ValueError.")
      .def(py::init(&make_python_scene), py::arg("positions"), py::arg("face_vertices"),
           py::arg("face_sizes"), py::arg("reflectance"), py::arg("emission"),
           py::arg("two_sided") = py::none(), py::arg("occludes") = py::none(),
           py::arg("lights") = py::none(), py::arg("world") = py::none())
      .def_property_readonly("face_count", [](const Scene& s) { return s.face_count; })
      .def_property_readonly("patch_count", [](const Scene& s) { return s.patches.size(); })
      .def_property_readonly(
          "total_area",
          [](const Scene& s) { return s.total_area / (s.frame.scale * s.frame.scale); },
          "one side of every patch, in the input's units")
      .def_property_readonly(
          "light_count", [](const Scene& s) { return s.lights.size(); },
          "lights solved as direct light: point, spot and sun lights, and the sky")
      .def_property_readonly(
          "skipped_faces", [](const Scene& s) { return face_notes(s.skipped); },
          "the input faces left out, a dict each: face, kind ('coincident_corners',\n"
          "'collinear_corners', 'crosses_itself', 'no_triangles'; 'too_small' with size and\n"
          "scene_size, the face's and the scene's diameters)")
      .def_property_readonly(
          "repaired_faces", [](const Scene& s) { return face_notes(s.repaired); },
          "the repairs of input faces solved after one, a dict each: face, kind\n"
          "('repeated_corners' with corners, how many were removed; 'not_planar' with bend,\n"
          "the corners' largest distance from the face's plane over its diameter, and\n"
          "triangles, how many planar ones it was split into)")
      .def_property_readonly(
          "coincident_faces",
          [](const Scene& s) {
            py::list out;
            for (const auto& pair : s.coincident) out.append(py::make_tuple(pair[0], pair[1]));
            return out;
          },
          "pairs of input faces that coincide somewhere (each surface counted once)")
      .def_property_readonly(
          "split_faces", [](const Scene& s) { return s.split_faces; },
          "input faces split along what lies on or passes through them")
      .def_property_readonly(
          "patches",
          [](const Scene& s) {
            py::list out;
            for (const Patch& p : s.patches) {
              py::list corners;
              for (int k = 0; k < p.corner_count; ++k) {
                const dvec3 c = s.frame.to_world(p.corners[static_cast<size_t>(k)]);
                corners.append(py::make_tuple(c.x, c.y, c.z));
              }
              py::list sides;
              for (const PatchSide& side : p.sides)
                sides.append(side.present ? py::object(py::make_tuple(side.face, side.face_side))
                                          : py::object(py::none()));
              const double area = p.area / (s.frame.scale * s.frame.scale);
              out.append(py::dict(py::arg("corners") = corners, py::arg("area") = area,
                                  py::arg("sides") = sides));
            }
            return out;
          },
          "the planar pieces solved: corners, area, and per side (front, back) the (face, face "
          "side) it shows or None");

  py::class_<PyResult>(m, "Result", "The solved leaf mesh with per-vertex radiance.")
      .def_readonly("positions", &PyResult::positions, "(V, 3) float64 vertex positions")
      .def_readonly("face_vertices", &PyResult::face_vertices,
                    "polygons' vertex indices, concatenated")
      .def_readonly("face_sizes", &PyResult::face_sizes, "(P,) vertices per polygon")
      .def_readonly("radiance", &PyResult::radiance, "(V, 3) float32 radiance per vertex")
      .def_readonly(
          "vertex_irradiance", &PyResult::vertex_irradiance,
          "(V, 3) float32 gathered radiance H per vertex (irradiance / pi), before the surface's "
          "reflectance and emission: radiance = emission + reflectance * H")
      .def_readonly("source_face", &PyResult::source_face, "(P,) input face of each polygon")
      .def_readonly("source_side", &PyResult::source_side, "(P,) 0 front, 1 back")
      .def_readonly("irradiance", &PyResult::irradiance,
                    "(P, 3) float32 area-average gathered radiance H per polygon (irradiance / pi)")
      .def_readonly("stats", &PyResult::stats, "statistics of the solve (dict)");

  // Defaults from SolveOptions{}: defined once, in the core.
  const SolveOptions defaults;
  // Kept for the module's life: pybind11 keeps a pointer to the text.
  static const std::string solve_doc =
      "Hierarchical radiosity. oracle: " + oracle_choices(" | ", " | ") + "; quality in\n" +
      "[0, 1] (0: no refinement); max_elements, time_budget (s): budgets; visibility:\n"
      "'exact' | 'sampled' (rays per sample); bounces: fixed iteration count instead of\n"
      "convergence; threads; progress(dict) callback; cancel: CancelToken;\n"
      "leaf_links: 'near' | 'all' | 'none', which links follow a split end down ('all': energy "
      "to 1e-3);\n"
      "cluster_separation: clusters of faces this many times their radii apart share one link\n"
      "(default from quality, 2 to 10; inf: none); dim_share: sides no ray brought direct light\n"
      "whose first-look light is below this share of the mean gather by rays, not links (0: "
      "none);\nfaint_share: with exact visibility, a sample whose unoccluded light from a link is\n"
      "below this share of its side's first-look light is shadowed by rays (0: all exact);\n"
      "memory_limit: bytes the elements and links "
      "may hold\n"
      "(default 3/4 of the available memory): refinement stops there (stats['stopped_by'] == "
      "'memory'),\n"
      "and a scene that cannot fit unrefined raises MemoryError before any work.\n"
      "progress gets pass, passes (fixed), phase, elements, leaves, links, seconds and fraction\n"
      "(never decreasing); with pass_results, the 'pass' reports carry 'result': that pass's\n"
      "solution, as solve() returns it. yield_to_interface: the solve's threads run at a lower\n"
      "CPU priority than the process's others (a UI beside the solve). reuse: a SolveReuse;\n"
      "the solve relights the one it keeps when only the lighting changed (stats['reused']).\n"
      "clock: a callable giving seconds from any origin, read instead of the steady clock for\n"
      "time_budget and the reported seconds (tests' fake clock).";
  m.def("solve", &py_solve, py::arg("scene"),
        py::arg("oracle") = std::string(oracle_name(defaults.oracle)),
        py::arg("quality") = defaults.quality, py::arg("max_elements") = py::none(),
        py::arg("time_budget") = py::none(),
        py::arg("visibility") = std::string(visibility_name(defaults.visibility)),
        py::arg("rays") = py::int_(defaults.rays), py::arg("bounces") = py::none(),
        py::arg("threads") = py::none(), py::arg("progress") = py::none(),
        py::arg("cancel") = py::none(), py::arg("min_element_area") = defaults.min_element_area,
        py::arg("leaf_links") = std::string(leaf_links_name(defaults.leaf_links)),
        py::arg("cluster_separation") = py::none(), py::arg("dim_share") = defaults.dim_share,
        py::arg("faint_share") = defaults.faint_share, py::arg("memory_limit") = py::none(),
        py::arg("pass_results") = false, py::arg("yield_to_interface") = false,
        py::arg("reuse") = py::none(), py::arg("clock") = py::none(), solve_doc.c_str());

  m.def(
      "quality_threshold",
      [](const std::string& oracle, double quality) {
        if (!(quality >= 0.0 && quality <= 1.0))
          throw std::invalid_argument("quality must lie in [0, 1]");
        return quality_threshold(read_oracle(oracle), quality);
      },
      py::arg("oracle"), py::arg("quality"),
      "The oracle's refinement threshold at a quality level.");
}

}  // namespace radiosity::python
