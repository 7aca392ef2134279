#!/usr/bin/env python3
"""The add-on on the public scenes of catalog.py, against Cycles' path trace.

    python3 bench/furnished/measure.py [--build build] [--addon-build DIR] [--blender blender]
        [--limit 300] [--memory 8] [--time-budget 0] [--qualities 0,default] [NAME ...]

For each scene (all without names; imported first by import_scene.py where its
.blend is missing), each step in its own Blender process, one at a time,
under `nice`, watched by this process:

1. Reference: the scene made diffuse-only (below), path traced at 320 x 240 by
   Cycles (32 bounces, no clamping, as scenes/scene_kit.py sets up the project's
   references) in two seeds of 128 samples (256 in all; the difference of the two
   measures the reference's own noise), and the emitter mask
   (tests/blender/render_compare.emitter_mask); cached in
   <build>/furnished/cache, keyed by the .blend's sha256, the settings and the
   Blender version, so a second run renders nothing.
2. For each quality (0 and the add-on's default): the add-on's solve
   (bpy.ops.radiosity.solve, sampled visibility, the scene's other settings,
   the time budget if given), its wall time, the solving process's peak
   resident memory (VmHWM, read by the process right after the solve) and the
   stats (status, elements, links); then the solution rendered as the Cycles
   agreement tests do (8 samples through the result's emission) and compared
   with the reference: exposure error (mean linear luminance over the
   reference's, minus 1) and median 8 x 8-block error
   (tests/blender/image_agreement.compare, emitter pixels left out).

Limits, so that the machine never dies: the solve may take --limit seconds
(from the moment the scene is loaded; loading and rendering get 600 s more)
and the process --memory GB resident (VmRSS sampled every 0.2 s; the process
is killed at the limit). A solve that hits either is recorded as such ("did
not finish within 300 s", "ran out at 8.0 GB") with the largest resident
memory seen. Prints a table; JSON in <build>/furnished/results.json.

Diffuse-only: every material is replaced by a Diffuse BSDF of the reflectance
the add-on reads from it (addon/read/export.py MaterialReader: Base Color, an image
texture's average, ...), plus its emission; where the add-on does not know the
node setup (the glTF importer's Glossy + Diffuse), the first Diffuse or
Principled BSDF's colour. Both the reference and the solve see those
materials, so the comparison measures the radiosity solution, not the
difference between a diffuse solver and glossy materials.
"""

import argparse
import hashlib
import json
import os
import pathlib
import signal
import subprocess
import sys
import time

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(ROOT / "tests" / "blender"))
import catalog  # noqa: E402

RESOLUTION = (320, 240)
REFERENCE_SAMPLES = 128      # per seed; two seeds
MASK_SAMPLES = 16
SOLUTION_SAMPLES = 8
RENDER_GRACE = 600.0         # seconds for loading and rendering beyond the solve's limit
POLL = 0.2
REFERENCE_VERSION = 2        # bump when the reference's rendering changes


# ---------------------------------------------------------------------------
# Inside Blender: the steps.

def make_diffuse(scene):
    """Every material a Diffuse BSDF of the reflectance the add-on reads (see the docstring)."""
    import bpy
    import numpy as np
    from radiosity.read import export
    reader = export.MaterialReader()
    for material in bpy.data.materials:
        rho, emission = reader.read(material)
        if material.name in reader.unknown and material.node_tree is not None:
            for node in material.node_tree.nodes:
                name = {"BSDF_DIFFUSE": "Color", "BSDF_PRINCIPLED": "Base Color"}.get(node.type)
                colour = reader._colour(node.inputs[name], material) if name else None
                if colour is not None:
                    rho = colour
                    break
        material.use_nodes = True
        nodes = material.node_tree.nodes
        nodes.clear()
        output = nodes.new("ShaderNodeOutputMaterial")
        diffuse = nodes.new("ShaderNodeBsdfDiffuse")
        diffuse.inputs["Color"].default_value = (*np.clip(rho, 0.0, 1.0), 1.0)
        shader = diffuse.outputs[0]
        if np.max(emission) > 0.0:
            emit = nodes.new("ShaderNodeEmission")
            emit.inputs["Color"].default_value = (*emission, 1.0)
            add = nodes.new("ShaderNodeAddShader")
            material.node_tree.links.new(diffuse.outputs[0], add.inputs[0])
            material.node_tree.links.new(emit.outputs[0], add.inputs[1])
            shader = add.outputs[0]
        material.node_tree.links.new(shader, output.inputs["Surface"])
        material.diffuse_color = (*np.clip(rho, 0.0, 1.0), 1.0)


def peak_memory_gb():
    for line in pathlib.Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) / 1024.0 ** 2
    return None


def worker(args):
    """One step in Blender: --step reference or --step solve; writes --out (JSON) and .npy files."""
    import bpy
    import numpy as np
    sys.path.insert(0, str(ROOT / "bench"))
    import in_blender
    in_blender.load_addon(args.addon_build)
    import render_compare as rc
    out = pathlib.Path(args.out)
    phase = out.with_suffix(".phase")
    scene = bpy.context.scene
    make_diffuse(scene)
    # As scenes/scene_kit.setup_render: enough bounces for a closed room to converge, no
    # clamping (Cycles' defaults, 4 diffuse bounces and indirect clamping, make it darker).
    scene.cycles.max_bounces = 32
    scene.cycles.diffuse_bounces = 32
    scene.cycles.sample_clamp_direct = 0.0
    scene.cycles.sample_clamp_indirect = 0.0
    result = dict(blender=bpy.app.version_string)
    if args.step == "reference":
        np.save(out.with_name("mask.npy"), rc.emitter_mask(scene, MASK_SAMPLES, RESOLUTION))
        for seed in (1, 2):
            image = rc.render_image(scene, REFERENCE_SAMPLES, RESOLUTION, seed=seed)
            np.save(out.with_name("seed%d.npy" % seed), image)
    else:
        settings = scene.radiosity
        settings.visibility = 'SAMPLED'
        if args.quality is not None:
            settings.quality = args.quality
        settings.time_budget = args.time_budget
        result.update(quality=settings.quality, oracle=settings.oracle, visibility=settings.visibility,
                      time_budget=settings.time_budget)
        phase.write_text("solving")
        start = time.perf_counter()
        outcome = bpy.ops.radiosity.solve()
        result["wall_seconds"] = time.perf_counter() - start
        result["peak_gb"] = peak_memory_gb()
        stats = settings.stats
        result.update(finished=sorted(outcome), status=stats.status, elements=stats.elements, links=stats.links,
                      solver_seconds=stats.seconds, iterations=stats.iterations, warning=stats.warning)
        out.write_text(json.dumps(result))
        phase.write_text("rendering")
        if 'FINISHED' in outcome:
            np.save(out.with_suffix(".npy"), rc.render_image(scene, SOLUTION_SAMPLES, RESOLUTION, seed=0))
    out.write_text(json.dumps(result))


# ---------------------------------------------------------------------------
# Outside: the runs, their limits, the comparison.

def rss_gb(pid):
    try:
        for line in pathlib.Path("/proc/%d/status" % pid).read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0 ** 2
    except (FileNotFoundError, ProcessLookupError):
        pass
    return 0.0


def run_limited(command, limit, memory_gb, phase_file=None, log=None):
    """Runs `command`, killing it past `limit` seconds (counted from when `phase_file`
    says "solving", if given; the whole run gets RENDER_GRACE more) or `memory_gb`
    resident. (outcome, seconds, largest resident GB seen): outcome "ok", "exit N",
    "time" or "memory"."""
    start = time.monotonic()
    solving_since = None
    peak = 0.0
    with open(log or os.devnull, "w") as sink:
        proc = subprocess.Popen(["nice", "-n", "10"] + command, stdout=sink, stderr=subprocess.STDOUT,
                                start_new_session=True)
        outcome = None
        while proc.poll() is None:
            time.sleep(POLL)
            peak = max(peak, rss_gb(proc.pid))
            now = time.monotonic()
            if phase_file is not None and solving_since is None and phase_file.exists():
                solving_since = now
            over_time = (solving_since is not None and now - solving_since > limit
                         and phase_file.read_text() == "solving") or now - start > limit + RENDER_GRACE
            if peak > memory_gb or over_time:
                outcome = "memory" if peak > memory_gb else "time"
                os.killpg(proc.pid, signal.SIGKILL)
                proc.wait()
                break
    seconds = time.monotonic() - (solving_since or start)
    return outcome or ("ok" if proc.returncode == 0 else "exit %d" % proc.returncode), seconds, peak


def blend_key(blend, blender):
    h = hashlib.sha256()
    h.update(pathlib.Path(blend).read_bytes())
    h.update(json.dumps([RESOLUTION, REFERENCE_SAMPLES, MASK_SAMPLES, REFERENCE_VERSION, blender]).encode())
    return h.hexdigest()[:16]


def blender_version(blender):
    text = subprocess.run([blender, "--version"], capture_output=True, text=True).stdout
    return text.splitlines()[0].strip() if text else blender


def step_command(args, blend, step, out, quality=None):
    command = [args.blender, "-b", str(blend), "--python", str(HERE / "measure.py"), "--",
               "--step", step, "--out", str(out), "--addon-build", args.addon_build,
               "--time-budget", str(args.time_budget)]
    if quality is not None:
        command += ["--quality", str(quality)]
    return command


def reference(args, name, blend, version):
    """(mean image, mask, noise dict) of the scene's path trace, rendered once and cached."""
    import numpy as np
    import image_agreement
    folder = catalog.furnished_dir(args.build) / "cache" / ("%s_%s" % (name, blend_key(blend, version)))
    if not (folder / "seed2.npy").exists():
        folder.mkdir(parents=True, exist_ok=True)
        print("[measure] %s: rendering the reference (2 x %d samples at %d x %d)"
              % (name, REFERENCE_SAMPLES, *RESOLUTION), flush=True)
        outcome, seconds, peak = run_limited(step_command(args, blend, "reference", folder / "reference.json"),
                                             args.reference_limit, args.memory, log=folder / "reference.log")
        if outcome != "ok":
            raise RuntimeError("%s: the reference did not render (%s after %.0f s, %.1f GB); see %s"
                               % (name, outcome, seconds, peak, folder / "reference.log"))
        print("[measure] %s: reference rendered in %.0f s" % (name, seconds), flush=True)
    a, b = np.load(folder / "seed1.npy"), np.load(folder / "seed2.npy")
    mask = np.load(folder / "mask.npy")
    half = image_agreement.compare(a, b, mask)
    noise = dict(exposure=abs(half["exposure"]) / 2, block=half["block"] / 2)
    return (a + b) / 2, mask, noise, folder


def solve(args, name, blend, quality, ref, mask, folder):
    import numpy as np
    import image_agreement
    tag = "q%s" % ("default" if quality is None else quality)
    out = folder / ("solve_%s_b%g.json" % (tag, args.time_budget))
    for stale in (out, out.with_suffix(".npy"), out.with_suffix(".phase")):
        stale.unlink(missing_ok=True)
    outcome, seconds, peak = run_limited(step_command(args, blend, "solve", out, quality), args.limit, args.memory,
                                         phase_file=out.with_suffix(".phase"), log=out.with_suffix(".log"))
    row = dict(scene=name, quality_asked=tag[1:], outcome=outcome, seconds_watched=seconds, largest_rss_gb=peak,
               limit_seconds=args.limit, limit_gb=args.memory, time_budget=args.time_budget)
    if out.exists():
        row.update(json.loads(out.read_text()))
    row["log"] = str(out.with_suffix(".log"))
    row["last_progress"] = last_progress(row["log"])
    if outcome == "time":
        row["result"] = "did not finish within %.0f s" % args.limit
    elif outcome == "memory":
        row["result"] = "ran out at %.1f GB" % args.memory
    elif outcome != "ok":
        row["result"] = "failed (%s; see %s)" % (outcome, out.with_suffix(".log"))
    if out.with_suffix(".npy").exists():
        e = image_agreement.compare(np.load(out.with_suffix(".npy")), ref, mask)
        row.update(exposure=e["exposure"], block=e["block"], blocks=e["blocks"])
        row.setdefault("result", "solved (%s)" % row.get("status", "?"))
    return row


def last_progress(log):
    """The add-on's last progress line in a solve's log (where a stopped solve was)."""
    lines = [x for x in pathlib.Path(log).read_text(errors="replace").splitlines() if x.startswith("Radiosity:")]
    return lines[-1][len("Radiosity:"):].strip() if lines else None


def fmt_row(r):
    def num(key, pattern, scale=1.0):
        return pattern % (r[key] * scale) if r.get(key) is not None else "-"
    quality = num("quality", "%.2f") if "quality" in r else r["quality_asked"]
    if quality == "default":
        quality = "default (%s)" % r.get("default_quality")
    result = r.get("result", "-")
    if r.get("last_progress") and "exposure" not in r:
        result += "; last progress: " + r["last_progress"]
    return "| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
        r["scene"], format(r["triangles"], ",") if r.get("triangles") else "?", r.get("addon_commit") or "?", quality,
        "%g" % r["time_budget"] if r["time_budget"] else "none", result,
        num("wall_seconds", "%.1f"), num("peak_gb", "%.2f") if r.get("peak_gb") else "(%.2f)" % r["largest_rss_gb"],
        format(r["elements"], ",") if "elements" in r else "-", format(r["links"], ",") if "links" in r else "-",
        num("exposure", "%+.1f %%", 100), num("block", "%.1f %%", 100))


HEADER = ["| scene | triangles | add-on | quality | time budget s | result | solve s | peak GB | elements | links "
          "| exposure | median block |", "|---|---|---|---|---|---|---|---|---|---|---|---|"]


def main():
    if "--step" in sys.argv:
        parser = argparse.ArgumentParser(prog="measure.py (worker)")
        parser.add_argument("--step", choices=("reference", "solve"))
        parser.add_argument("--out")
        parser.add_argument("--addon-build")
        parser.add_argument("--quality", type=float)
        parser.add_argument("--time-budget", type=float, default=0.0)
        worker(parser.parse_args(sys.argv[sys.argv.index("--") + 1:]))
        return
    parser = argparse.ArgumentParser(description="the add-on on public scenes, against a path trace")
    parser.add_argument("--build", default=str(ROOT / "build"), help="where furnished/ goes (downloads, .blend, results)")
    parser.add_argument("--addon-build", help="build tree whose addon/ is loaded (default: --build)")
    parser.add_argument("--blender", default="blender")
    parser.add_argument("--limit", type=float, default=300.0, help="seconds a solve may take")
    parser.add_argument("--reference-limit", type=float, default=3600.0, help="seconds a reference may take")
    parser.add_argument("--memory", type=float, default=8.0, help="GB a Blender process may hold resident")
    parser.add_argument("--time-budget", type=float, default=0.0, help="the add-on's Time Limit setting (0: none)")
    parser.add_argument("--qualities", default="0,default", help="comma-separated; 'default': the add-on's")
    parser.add_argument("--table-only", action="store_true", help="only print the table of results.json")
    parser.add_argument("names", nargs="*")
    args = parser.parse_args()
    args.build = str(pathlib.Path(args.build).resolve())
    args.addon_build = str(pathlib.Path(args.addon_build or args.build).resolve())
    qualities = [None if q == "default" else float(q) for q in args.qualities.split(",")]
    if args.table_only:
        return write_results(args, [])
    version = blender_version(args.blender)
    out = catalog.furnished_dir(args.build)
    imported = out / "imported.json"
    rows = []
    for name in args.names or catalog.SCENES:
        blend = out / (name + ".blend")
        if not blend.exists():
            subprocess.run(["nice", "-n", "10", args.blender, "-b", "--factory-startup", "--python",
                            str(HERE / "import_scene.py"), "--", "--build", args.build, name], check=True)
        triangles = json.loads(imported.read_text()).get(name, {}).get("triangles") if imported.exists() else None
        ref, mask, noise, folder = reference(args, name, blend, version)
        print("[measure] %s: reference noise: exposure %.2f %%, median block %.2f %%"
              % (name, 100 * noise["exposure"], 100 * noise["block"]), flush=True)
        for quality in qualities:
            row = solve(args, name, blend, quality, ref, mask, folder)
            row.update(triangles=triangles, reference_noise=noise, blender=version)
            rows.append(row)
            print(fmt_row(row), flush=True)
    for row in rows:
        row.update(addon_build=args.addon_build, addon_commit=git_commit(args.addon_build))
    write_results(args, rows)


def write_results(args, rows):
    """Merges `rows` into <build>/furnished/results.json (keeping the other scenes, qualities,
    budgets and add-on builds measured before) and writes the table to results.md."""
    out = catalog.furnished_dir(args.build)
    defaults = json.loads((pathlib.Path(args.addon_build) / "addon" / "radiosity" / "solver_defaults.json").read_text())
    results = out / "results.json"
    def key(r):
        return r["scene"], r["quality_asked"], r["time_budget"], r.get("addon_build"), r.get("addon_commit")
    measured = {key(r) for r in rows}
    earlier = json.loads(results.read_text())["rows"] if results.exists() else []
    rows = [r for r in earlier if key(r) not in measured] + rows
    for row in rows:
        if "log" not in row:   # rows of the first version of this script
            logs = sorted((out / "cache").glob("%s_*/solve_q%s_b%g.log" % (row["scene"], row["quality_asked"],
                                                                          row["time_budget"])))
            row["log"] = str(logs[-1]) if logs else None
            row["last_progress"] = last_progress(logs[-1]) if logs else None
        row.setdefault("default_quality", defaults["quality"])
    rows.sort(key=lambda r: (list(catalog.SCENES).index(r["scene"]) if r["scene"] in catalog.SCENES else 99,
                             r.get("addon_commit") or "", r["time_budget"], r["quality_asked"]))
    table = "\n".join(HEADER + [fmt_row(r) for r in rows])
    print(table)
    results.write_text(json.dumps(dict(rows=rows), indent=1))
    (out / "results.md").write_text(table + "\n")
    print("[measure] wrote %s" % results)


def git_commit(build):
    """The commit of the source tree a build tree sits in (its parent), if it is a git checkout."""
    tree = str(pathlib.Path(build).parent)
    run = subprocess.run(["git", "-C", tree, "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
    changed = subprocess.run(["git", "-C", tree, "status", "--porcelain", "--", "native", "addon"],
                             capture_output=True, text=True).stdout.strip()
    return (run.stdout.strip() + (" + uncommitted native/addon changes" if changed else "")) or None


if __name__ == "__main__":
    main()
