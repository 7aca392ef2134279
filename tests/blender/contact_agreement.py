"""How issue 12 measures a radiosity solution against a path trace (inside Blender):
the cases, the cached path-traced reference and its noise, the emitter mask,
and the two numbers of the acceptance. Used by tests/blender/test_contact.py
and bench/contact_gap.py, so the test and the bench measure the same thing.

- Images: 128 x 128 pixels from the scene's camera, Standard view transform,
  linear radiance read back from OpenEXR (render_compare.render_image).
- Emitter pixels are left out of every statistic (render_compare.emitter_mask).
- Exposure error and median block error: image_agreement.compare.
- Reference: the original scene path traced (32 bounces, no clamping) with
  pairs of seeds until its measured noise is low enough; it is their mean, and
  the difference of the two halves' means measures its noise. Cached as .npy under
  <build>/contact_cache, keyed by the case's scene and parameters, the image
  size, the samples, the seed, the Blender version and the source of the
  scene builders, so a second run renders nothing.
"""

import hashlib
import json
import os
import pathlib
import sys

import bpy
import numpy as np
from radiosity.model import oracles

import image_agreement
import render_compare as rc

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scenes"))
import build_scene  # noqa: E402
import scene_kit  # noqa: E402

RESOLUTION = (128, 128)
# Seeds of this many samples are added in pairs until the reference's noise
# is below NOISE_TARGET (two seeds in most cases; more where a bright patch
# the light cannot be sampled towards lights the room, as the ceiling just
# above the Cornell box's light at a 1 cm gap), at most MAX_SEEDS.
REFERENCE_SAMPLES = 128
MAX_SEEDS = 8
NOISE_TARGET = dict(exposure=0.003, block=0.01)   # a tenth and a sixth of the tolerances
MASK_SAMPLES = 16
# The solution has no noise of its own (emission only): samples anti-alias.
SOLUTION_SAMPLES = 8
ORACLES = oracles.IDENTIFIERS
QUALITIES = (0.3, 0.5, 0.8)

# label: (scene, builder parameters)
CASES = {
    "cornell_box": ("cornell_box", {}),    # as published: the light 0.1 mm under the ceiling
    "cornell_box_1mm": ("cornell_box", {"gap": 1e-3}),
    "cornell_box_1cm": ("cornell_box", {"gap": 1e-2}),
    "cornell_box_5cm": ("cornell_box", {"gap": 5e-2}),
    "box_on_floor": ("box_on_floor", {}),
    "lamp_on_table": ("lamp_on_table", {}),
    "picture_on_wall": ("picture_on_wall", {}),
    # Issue 15: each kind of light alone, then all together (tests/blender/test_lights.py).
    "lights_point": ("lights_room", {"lights": ["point"]}),
    "lights_spot": ("lights_room", {"lights": ["spot"]}),
    "lights_sun": ("lights_room", {"lights": ["sun"]}),
    "lights_world": ("lights_room", {"lights": ["world"]}),
    "lights_all": ("lights_room", {}),
    # Finely tessellated objects (bench/tessellated_room.py): the sphere alone, then with Suzanne.
    "tessellated_sphere": ("tessellated_room", {"objects": ["rug", "sphere", "box"]}),
    "tessellated_monkey": ("tessellated_room", {}),
}
GAPS = (("0.1 mm", "cornell_box"), ("1 mm", "cornell_box_1mm"), ("1 cm", "cornell_box_1cm"),
        ("5 cm", "cornell_box_5cm"))
# Bump when the way references are rendered changes, to drop old cache entries.
RENDER_VERSION = 1


def build_dir():
    """The build tree this Blender loaded the add-on from (<build>/addon/radiosity)."""
    import radiosity
    return pathlib.Path(radiosity.__file__).resolve().parents[2]


def build_case(label):
    """A fresh file holding only the case's scene; returns the scene."""
    name, params = CASES[label]
    scene = scene_kit.empty_file()
    scene.name = label
    build_scene.build(name, scene, **params)
    scene.view_layers[0].update()
    return scene


def cache_key(label, samples, seed):
    name, params = CASES[label]
    h = hashlib.sha256()
    for source in ("scene_kit.py", "build_scene.py", name + ".py"):
        h.update((ROOT / "scenes" / source).read_bytes())
    h.update(json.dumps([name, sorted(params.items()), RESOLUTION, samples, seed, bpy.app.version_string,
                         RENDER_VERSION]).encode())
    return "%s_%s" % (label, h.hexdigest()[:16])


def _cached(path, render):
    if path.exists():
        return np.load(path), True
    image = render()
    path.parent.mkdir(parents=True, exist_ok=True)
    np.save(path, image)
    return image, False


class Reference:
    """The path-traced reference of a case: mean image, the seeds' images, the
    emitter mask; `rendered` counts what was not in the cache."""

    def __init__(self, label, scene, cache_dir=None):
        cache_dir = pathlib.Path(cache_dir or build_dir() / "contact_cache")
        self.mask, hit = _cached(cache_dir / (cache_key(label, MASK_SAMPLES, "mask") + ".npy"),
                                 lambda: rc.emitter_mask(scene, MASK_SAMPLES, RESOLUTION))
        self.seeds, self.rendered = [], int(not hit)
        for seed in range(1, MAX_SEEDS + 1):
            image, hit = _cached(cache_dir / (cache_key(label, REFERENCE_SAMPLES, seed) + ".npy"),
                                 lambda: rc.render_image(scene, REFERENCE_SAMPLES, RESOLUTION, seed=seed))
            self.seeds.append(image)
            self.rendered += not hit
            if seed % 2 == 0 and all(v <= NOISE_TARGET[k] for k, v in self.noise().items()):
                break
        self.image = np.mean(self.seeds, axis=0)

    def noise(self):
        """Errors the reference's own noise alone causes. The mean of the first
        half of the seeds and that of the second differ by twice what the mean
        of all carries (their errors have the same spread as its, doubled), so
        half their difference measures it."""
        half = len(self.seeds) // 2
        a, b = np.mean(self.seeds[:half], axis=0), np.mean(self.seeds[half:2 * half], axis=0)
        e = image_agreement.compare(a, b, self.mask)
        return dict(exposure=abs(e["exposure"]) / 2, block=e["block"] / 2)


def solve_and_render(scene, oracle, quality):
    """Solve at the default settings but oracle and quality; (render of the solution, stats)."""
    scene.radiosity.oracle = oracle
    scene.radiosity.quality = quality
    if bpy.ops.radiosity.solve() != {'FINISHED'}:
        raise RuntimeError("solve of %s (%s, %.1f) did not finish" % (scene.name, oracle, quality))
    return rc.render_image(scene, SOLUTION_SAMPLES, RESOLUTION, seed=0), scene.radiosity.stats


def save_pngs(folder, label, reference, solutions):
    """reference and {tag: image} as sRGB PNGs in `folder` (for looking at them)."""
    os.makedirs(folder, exist_ok=True)
    rc.save_png(reference.image, os.path.join(folder, label + "_cycles.png"))
    mask = np.repeat(reference.mask[:, :, None], 3, axis=2)
    rc.save_png(np.where(mask, [1.0, 0.0, 1.0], reference.image), os.path.join(folder, label + "_mask.png"))
    for tag, image in solutions.items():
        rc.save_png(image, os.path.join(folder, "%s_%s.png" % (label, tag)))


MEAN_TOLERANCE = 0.03
BLOCK_TOLERANCE = 0.06
# The reference must resolve the tolerances: its noise alone a fraction of them.
NOISE_FRACTION = 0.25


def assert_agreement(test, label, qualities=QUALITIES, oracles=ORACLES):
    """Asserts (on `test`, a TestCase) that each of `oracles` at `qualities` agrees with the
    path trace of the case `label` within the tolerances, printing the numbers."""
    scene = build_case(label)
    reference = Reference(label, scene)
    noise = reference.noise()
    print("[agreement] %s reference: %d seeds x %d samples%s; its noise: exposure %.2f %%, median block %.2f %%; "
          "emitter pixels left out: %.1f %%"
          % (label, len(reference.seeds), REFERENCE_SAMPLES, " (cached)" if not reference.rendered else "",
             100 * noise["exposure"], 100 * noise["block"], 100 * reference.mask.mean()), flush=True)
    test.assertLess(noise["exposure"], NOISE_FRACTION * MEAN_TOLERANCE)
    test.assertLess(noise["block"], NOISE_FRACTION * BLOCK_TOLERANCE)
    renders = {}
    for oracle in oracles:
        for quality in qualities:
            image, stats = solve_and_render(scene, oracle, quality)
            renders["%s_%.1f" % (oracle.lower(), quality)] = image
            e = image_agreement.compare(image, reference.image, reference.mask)
            print("[agreement] %s %-10s q=%.1f: exposure %+6.1f %%, median block error %5.1f %% "
                  "(%d blocks; %d elements, %s)" % (label, oracle.lower(), quality, 100 * e["exposure"],
                                                    100 * e["block"], e["blocks"], stats.elements, stats.status),
                  flush=True)
            numbers = "%s %s q=%.1f: exposure %+.1f %% (tolerance %.0f %%), median block error %.1f %% " \
                      "(tolerance %.0f %%)" % (label, oracle.lower(), quality, 100 * e["exposure"],
                                               100 * MEAN_TOLERANCE, 100 * e["block"], 100 * BLOCK_TOLERANCE)
            with test.subTest(oracle=oracle, quality=quality):
                test.assertLess(abs(e["exposure"]), MEAN_TOLERANCE, numbers)
                test.assertLess(e["block"], BLOCK_TOLERANCE, numbers)
    folder = os.environ.get("RADIOSITY_TEST_IMAGES")
    if folder:
        save_pngs(folder, label, reference, renders)
