"""The numbers issue 12 judges a render by against a path-traced reference
(numpy only, no bpy: the study, bench/study.py, uses them outside Blender too).

- Exposure error: mean linear Rec. 709 luminance (not clipped: radiance as
  rendered) of the image over the reference's, minus 1; signed, > 0 is too
  bright. Emitter pixels are left out (`mask`, render_compare.emitter_mask):
  they are exact on both sides and would only dilute the error.
- Block error: the image cut into 8 x 8-pixel blocks; per block the relative
  difference of the mean luminances of its non-emitter pixels, relative to the
  reference block floored at a tenth of the image mean (nearly black blocks are
  judged in absolute terms); blocks more than half emitter are left out; the
  median over the blocks.
"""

import numpy as np

LUMINANCE = np.array([0.2126, 0.7152, 0.0722])
BLOCK = 8


def luminance(image):
    return np.asarray(image, dtype=np.float64)[..., :3] @ LUMINANCE


def block_means(lum, keep, block=BLOCK):
    """Per block: mean of the kept pixels, and the fraction of its pixels kept
    (a partial block at the right or bottom edge is dropped)."""
    h, w = lum.shape
    rows, cols = h // block, w // block
    shape = (rows, block, cols, block)
    kept = keep[:rows * block, :cols * block].reshape(shape).sum(axis=(1, 3))
    total = np.where(keep, lum, 0.0)[:rows * block, :cols * block].reshape(shape).sum(axis=(1, 3))
    return total / np.maximum(kept, 1), kept / block ** 2


def compare(image, reference, mask=None):
    """dict(exposure: signed relative error of the mean luminance, block: median
    block error, blocks: how many blocks were judged, mean, reference_mean)."""
    a, b = luminance(image), luminance(reference)
    keep = np.ones(a.shape, dtype=bool) if mask is None else ~np.asarray(mask, dtype=bool)
    mean_a, mean_b = a[keep].mean(), b[keep].mean()
    block_a, fraction = block_means(a, keep)
    block_b, _ = block_means(b, keep)
    judged = fraction >= 0.5
    error = np.abs(block_a - block_b) / np.maximum(block_b, 0.1 * mean_b)
    return dict(exposure=float(mean_a / mean_b - 1.0), block=float(np.median(error[judged])),
                blocks=int(judged.sum()), mean=float(mean_a), reference_mean=float(mean_b))
