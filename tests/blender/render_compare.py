"""Helpers of the Cycles agreement tests: small renders, region statistics.

A radiosity solution is compared with a path-traced Cycles render of the same
scene from the same camera (Standard view transform): the solution is rendered
through its Emission material (the originals hidden), the reference with the
originals and their lights. Both images are read back as linear floats from
OpenEXR, clipped at 1 (what the Standard view transform displays) and reduced
to luminance; the comparison is on the image mean and on the means of a grid
of regions.
"""

import os
import tempfile

import bpy
import numpy as np

LUMINANCE = np.array([0.2126, 0.7152, 0.0722])


def render_image(scene, samples, resolution=(96, 72), seed=None):
    """Render `scene` with Cycles; (H, W, 3) linear float image. `seed`: Cycles'
    sampling seed (default: the scene's)."""
    scene.render.engine = 'CYCLES'
    scene.cycles.device = 'CPU'
    scene.cycles.samples = samples
    if seed is not None:
        scene.cycles.seed = seed
        scene.cycles.use_animated_seed = False
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False
    scene.render.resolution_x, scene.render.resolution_y = resolution
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = 'OPEN_EXR'
    scene.render.image_settings.color_depth = '32'
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "render.exr")
        scene.render.filepath = path
        with bpy.context.temp_override(scene=scene):
            bpy.ops.render.render(write_still=True, scene=scene.name)
        image = bpy.data.images.load(path)
        pixels = np.empty(len(image.pixels), dtype=np.float32)
        image.pixels.foreach_get(pixels)
        bpy.data.images.remove(image)
    w, h = resolution
    return pixels.reshape(h, w, 4)[::-1, :, :3]   # top row first


def emitter_objects(scene):
    """Objects that emit: lights, and meshes with a material the add-on reads as emitting."""
    from radiosity.read import export
    reader = export.MaterialReader()
    return [o for o in scene.objects if o.type == 'LIGHT' or (
        o.type == 'MESH' and any(reader.read(s.material)[1].max() > 0 for s in o.material_slots))]


def emitter_mask(scene, samples=16, resolution=(96, 72)):
    """(H, W) bool: the pixels an emitter covers or reaches through the pixel filter.

    A render in which every other mesh is a holdout (black, but still hiding
    what lies behind it) and nothing bounces; every pixel it lights, widened by
    one pixel: an emitter many times brighter than a wall spreads into its
    neighbours through the filter, at a weight the samples may miss."""
    emitters = set(emitter_objects(scene))
    others = [o for o in scene.objects if o.type == 'MESH' and o not in emitters]
    bounces = scene.cycles.max_bounces
    for obj in others:
        obj.is_holdout = True
    scene.cycles.max_bounces = 0
    try:
        image = render_image(scene, samples, resolution, seed=0)
    finally:
        for obj in others:
            obj.is_holdout = False
        scene.cycles.max_bounces = bounces
    covered = image.max(axis=2) > 0.0
    grown = covered.copy()   # the 3 x 3 neighbourhood of every covered pixel
    grown[1:, :] |= covered[:-1, :]
    grown[:-1, :] |= covered[1:, :]
    rows = grown.copy()
    grown[:, 1:] |= rows[:, :-1]
    grown[:, :-1] |= rows[:, 1:]
    return grown


def save_png(image, path):
    """Write a linear image as an sRGB PNG (for looking at it)."""
    h, w, _ = image.shape
    img = bpy.data.images.new("compare", w, h, float_buffer=True)
    rgba = np.ones((h, w, 4), dtype=np.float32)
    rgba[:, :, :3] = image[::-1]
    img.pixels.foreach_set(rgba.ravel())
    img.filepath_raw = path
    img.file_format = 'PNG'
    img.save()
    bpy.data.images.remove(img)


def luminance(image):
    return np.clip(image, 0.0, 1.0) @ LUMINANCE


def region_means(image, grid=(4, 3)):
    """Mean luminance of each cell of a grid (columns, rows) over the image."""
    lum = luminance(image)
    h, w = lum.shape
    cols, rows = grid
    return np.array([[lum[r * h // rows:(r + 1) * h // rows, c * w // cols:(c + 1) * w // cols].mean()
                      for c in range(cols)] for r in range(rows)])


def compare(solution, reference, grid=(4, 3)):
    """(relative error of the mean, worst relative error of a region, region tables)."""
    a, b = luminance(solution).mean(), luminance(reference).mean()
    ra, rb = region_means(solution, grid), region_means(reference, grid)
    # Relative to the region's reference, floored at a tenth of the image mean so
    # that nearly black regions are judged in absolute terms.
    region_error = np.abs(ra - rb) / np.maximum(rb, 0.1 * b)
    return abs(a - b) / b, float(region_error.max()), ra, rb
