"""Atheris harness of the Python API of `_radiosity` (`make fuzz`, tools/fuzz.py).

Each input is read with atheris' FuzzedDataProvider into one of: a Scene and a
small solve (vertices, faces of any size with any indices, materials, light
dicts with any keys and values, a world colour, solve options in and out of
range), or a batch of kernel calls (form_factor, form_factor_gradient,
visible_form_factor exact and sampled, visible_polygon, quality_threshold).
Every call must return finite, well-formed output or raise ValueError; anything
else raises here, which atheris reports with the input that caused it. A crash
of the module itself (a signal, a sanitizer report) is caught by libFuzzer.

tools/fuzz.py runs it on a module built with clang and
-fsanitize=address,undefined,fuzzer-no-link (so libFuzzer sees the C++
coverage), with atheris' ASan runtime preloaded.

    python atheris_api.py --path DIR_WITH__radiosity --path DIR_WITH__radiosity_kernels \
        [libFuzzer options] [corpus dirs]
"""

import base64
import math
import os
import sys


def _setup_path():
    args = sys.argv[1:]
    rest = [sys.argv[0]]
    i = 0
    while i < len(args):
        if args[i] == "--path" and i + 1 < len(args):
            sys.path.insert(0, args[i + 1])
            i += 2
        else:
            rest.append(args[i])
            i += 1
    sys.argv[:] = rest


_setup_path()
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tests", "native"))

import atheris  # noqa: E402
import numpy as np  # noqa: E402

with atheris.instrument_imports():
    import fuzz_cases  # noqa: E402  (the output checks the slice uses)

import _radiosity as rad  # noqa: E402
import _radiosity_kernels  # noqa: E402

np.seterr(all="ignore")

ORACLES = ["standard", "perceptual", "gradient", "noticeable", "bf", ""]


def number(fdp, hostile=True):
    """A float: mostly ordinary, sometimes any double (inf, nan, subnormal, 1e308)."""
    pick = fdp.ConsumeIntInRange(0, 9)
    if hostile and pick == 0:
        return fdp.ConsumeFloat()
    if pick == 1:
        return fdp.ConsumeRegularFloat()
    return fdp.ConsumeFloatInRange(-10.0, 10.0)


def vec3(fdp, hostile=True):
    return np.array([number(fdp, hostile) for _ in range(3)])


def polygon(fdp, n_max=8):
    n = fdp.ConsumeIntInRange(3, n_max)
    if fdp.ConsumeBool():
        return np.array([vec3(fdp, hostile=False) for _ in range(n)])
    centre, radius = vec3(fdp, hostile=False), 10.0 ** fdp.ConsumeFloatInRange(-12, 3)
    normal = vec3(fdp, hostile=False)
    length = np.linalg.norm(normal)
    normal = normal / length if length > 0 else np.array([0.0, 0.0, 1.0])
    helper = np.array([1.0, 0, 0]) if abs(normal[0]) < 0.9 else np.array([0, 1.0, 0])
    t1 = np.cross(helper, normal)
    t1 /= np.linalg.norm(t1)
    t2 = np.cross(normal, t1)
    angles = np.sort([fdp.ConsumeFloatInRange(0, 2 * math.pi) for _ in range(n)])
    return np.array([centre + radius * (math.cos(a) * t1 + math.sin(a) * t2) for a in angles])


def light(fdp):
    kind = ["point", "spot", "sun", "area"][fdp.ConsumeIntInRange(0, 3)]
    d = {"type": kind}
    keys = ["intensity", "position", "radius", "shape", "direction", "cos_half_angle", "blend_width",
            "cosine_falloff", "irradiance", "angle", "colour"]
    for key in keys:
        if not fdp.ConsumeBool():
            continue
        if key in ("intensity", "position", "direction", "irradiance", "colour"):
            d[key] = vec3(fdp)
        elif key == "shape":
            d[key] = ["sphere", "disk", "cube"][fdp.ConsumeIntInRange(0, 2)]
        elif key == "cosine_falloff":
            d[key] = fdp.ConsumeBool()
        else:
            d[key] = number(fdp)
    return d


def scene_and_solve(fdp):
    vertices = fdp.ConsumeIntInRange(0, 48)
    positions = np.array([vec3(fdp, hostile=fdp.ConsumeIntInRange(0, 15) == 0) for _ in range(vertices)]).reshape(-1, 3)
    scale = 10.0 ** fdp.ConsumeIntInRange(-35, 35) if fdp.ConsumeIntInRange(0, 3) == 0 else 1.0
    positions = positions * scale
    faces = fdp.ConsumeIntInRange(1, 24)
    sizes, indices = [], []
    for _ in range(faces):
        size = fdp.ConsumeIntInRange(3, 8) if fdp.ConsumeIntInRange(0, 31) else fdp.ConsumeIntInRange(-2, 40)
        sizes.append(size)
        for _ in range(max(size, 0)):
            if vertices and fdp.ConsumeIntInRange(0, 63):
                indices.append(fdp.ConsumeIntInRange(0, vertices - 1))  # repeats allowed
            else:
                indices.append(fdp.ConsumeIntInRange(-2, vertices + 2))
    # Duplicate faces (coincident copies sharing indices, or reversed) now and then.
    for _ in range(fdp.ConsumeIntInRange(0, 3) and fdp.ConsumeIntInRange(0, 16)):
        if sizes and sizes[0] >= 3:
            sizes.append(sizes[0])
            first = indices[:sizes[0]]
            indices.extend(first[::-1] if fdp.ConsumeBool() else first)
    nf = len(sizes)
    reflectance = np.array([[fdp.ConsumeFloatInRange(0, 1) if fdp.ConsumeIntInRange(0, 31) else number(fdp)
                             for _ in range(3)] for _ in range(nf)])
    emission = np.zeros((nf, 3))
    for f in range(nf):
        if fdp.ConsumeIntInRange(0, 3) == 0:
            e = fdp.ConsumeFloatInRange(0, 100) * 10.0 ** fdp.ConsumeIntInRange(-300, 300)
            emission[f] = e if fdp.ConsumeIntInRange(0, 31) else number(fdp)
    kwargs = {}
    if fdp.ConsumeBool():
        kwargs["two_sided"] = np.array([fdp.ConsumeBool() for _ in range(nf)])
    if fdp.ConsumeIntInRange(0, 3) == 0:
        kwargs["occludes"] = np.array([fdp.ConsumeBool() for _ in range(nf)])
    if fdp.ConsumeIntInRange(0, 2) == 0:
        kwargs["lights"] = [light(fdp) for _ in range(fdp.ConsumeIntInRange(0, 3))]
    if fdp.ConsumeIntInRange(0, 3) == 0:
        kwargs["world"] = vec3(fdp)
    scene = rad.Scene(positions, np.array(indices, np.int64), np.array(sizes, np.int64), reflectance, emission,
                      **kwargs)
    options = dict(oracle=ORACLES[fdp.ConsumeIntInRange(0, 4) if fdp.ConsumeIntInRange(0, 15) else 0],
                   quality=fdp.ConsumeFloatInRange(0, 0.6) if fdp.ConsumeIntInRange(0, 15) else number(fdp),
                   max_elements=fdp.ConsumeIntInRange(1, 200) if fdp.ConsumeIntInRange(0, 15) else
                   fdp.ConsumeIntInRange(-5, 5),
                   visibility=["exact", "sampled", "none"][fdp.ConsumeIntInRange(0, 2) if fdp.ConsumeIntInRange(0, 15) else 0],
                   rays=fdp.ConsumeIntInRange(1, 16) if fdp.ConsumeIntInRange(0, 15) else fdp.ConsumeIntInRange(-2, 70000),
                   threads=fdp.ConsumeIntInRange(1, 2) if fdp.ConsumeIntInRange(0, 15) else fdp.ConsumeIntInRange(-2, 4),
                   min_element_area=10.0 ** fdp.ConsumeFloatInRange(-4, -1),
                   leaf_links=["near", "none", "all", "some"][fdp.ConsumeIntInRange(0, 3)])
    if fdp.ConsumeBool():
        options["bounces"] = fdp.ConsumeIntInRange(1, 4) if fdp.ConsumeIntInRange(0, 15) else fdp.ConsumeIntInRange(-2, 2)
    if fdp.ConsumeIntInRange(0, 3) == 0:
        options["cluster_separation"] = number(fdp)
    result = rad.solve(scene, **options)
    fuzz_cases.check_result(result, nf)


def kernels(fdp):
    for _ in range(fdp.ConsumeIntInRange(1, 8)):
        name = ["form_factor", "form_factor_gradient", "visible_form_factor", "visible_polygon",
                "quality_threshold"][fdp.ConsumeIntInRange(0, 4)]
        try:
            if name == "quality_threshold":
                args, kwargs = (ORACLES[fdp.ConsumeIntInRange(0, 4)], number(fdp)), {}
            else:
                poly = polygon(fdp)
                point = vec3(fdp, hostile=fdp.ConsumeIntInRange(0, 31) == 0)
                if fdp.ConsumeBool():  # on or next to the emitter
                    point = poly[fdp.ConsumeIntInRange(0, len(poly) - 1)] + 10.0 ** fdp.ConsumeIntInRange(-15, 0) * point
                args, kwargs = (point, vec3(fdp, hostile=fdp.ConsumeIntInRange(0, 31) == 0), poly), {}
                if name in ("visible_form_factor", "visible_polygon"):
                    m = fdp.ConsumeIntInRange(0, 12)
                    occ = np.array([[vec3(fdp, hostile=False) for _ in range(3)] for _ in range(m)]).reshape(-1, 3, 3)
                    if m and fdp.ConsumeBool():  # between the point and the emitter
                        occ = point + fdp.ConsumeFloatInRange(0, 1) * (poly.mean(axis=0) - point) + 0.1 * occ
                    args = args + (occ,)
                    if name == "visible_form_factor":
                        kwargs["mode"] = ["exact", "sampled"][fdp.ConsumeIntInRange(0, 1)]
                        kwargs["rays"] = fdp.ConsumeIntInRange(1, 64)
                        if m and fdp.ConsumeBool():
                            kwargs["faces"] = np.array([fdp.ConsumeIntInRange(0, 3) for _ in range(m)])
                            kwargs["own_faces"] = tuple(fdp.ConsumeIntInRange(0, 3)
                                                        for _ in range(fdp.ConsumeIntInRange(0, 2)))
            fuzz_cases.run_kernel_call(rad, _radiosity_kernels, name, args, kwargs)
        except ValueError:
            pass


# With FUZZ_FINDINGS_FILE set (tools/fuzz.py does), a finding in Python (non-finite
# or malformed output, an exception other than ValueError) is appended there as
# "class<TAB>base64 of the input" and fuzzing goes on, so one known bug does not
# end every run; crashes of the module itself still stop it (libFuzzer saves them).
FINDINGS = os.environ.get("FUZZ_FINDINGS_FILE")


def test_one_input(data):
    fdp = atheris.FuzzedDataProvider(data)
    try:
        if fdp.ConsumeIntInRange(0, 3) == 0:
            kernels(fdp)
        else:
            scene_and_solve(fdp)
    except ValueError:
        pass  # a clean refusal
    except Exception as err:  # noqa: BLE001  (a finding)
        if not FINDINGS:
            raise
        what = "%s: %s" % (type(err).__name__, fuzz_cases.message_class(err))
        with open(FINDINGS, "a") as out:
            out.write("%s\t%s\n" % (what, base64.b64encode(data).decode()))


def main():
    atheris.Setup(sys.argv, test_one_input)
    atheris.Fuzz()


if __name__ == "__main__":
    main()
