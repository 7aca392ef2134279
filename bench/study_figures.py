"""Equal-size comparison figures (the source's Figures 40-47): per scene, the
refined reference and each oracle's solution with (about) the same number of
leaves, shaded, as a mesh (the edges the camera sees over a faded image), and
edge filtered (the centre-surround filter the error metric uses); the Cycles
path-traced reference in the last row."""

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402

import study_config  # noqa: E402


def display(rgb):
    """Linear RGB as the Standard view transform shows it (clipped, sRGB-encoded)."""
    c = np.clip(rgb, 0.0, 1.0)
    return np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1 / 2.4) - 0.055)


def comparison_figures(metric, studies, out):
    paths = []
    for st in studies:
        rows = [("refined reference (%s, %d leaves), exposure %+.1f %%"
                 % (st.reference[0], _refined(st)["leaves"], 100 * _refined(st)["exposure_cycles"]), "refined")]
        for oracle in study_config.ORACLES:
            r = st.comparison.get(oracle)
            if r is not None:
                rows.append(("%s, %d leaves, DoG err %.2e, exposure %+.1f %%"
                             % (oracle, r["leaves"], r["dog_refined"], 100 * r["exposure_cycles"]), r["tag"]))
        rows.append(("Cycles path traced (%d x %d spp)" % (st.noise["seeds"], st.noise["samples_per_seed"]),
                     "cycles"))
        ref_dog = metric.read_image(str(st.image_path("refined_dog")))[:, :, 0]
        scale = float(np.percentile(np.abs(ref_dog), 99.5)) or 1.0
        fig, axes = plt.subplots(len(rows), 3, figsize=(12, 3.0 * len(rows)), squeeze=False)
        for i, (label, tag) in enumerate(rows):
            img = display(metric.read_image(str(st.image_path(tag))))
            h, w, _ = img.shape
            axes[i][0].imshow(img)
            axes[i][0].set_title(label, fontsize=8)
            edges = st.image_path(tag + "_edges", ".npy")
            axes[i][1].imshow(0.35 + 0.65 * img)
            if edges.exists():
                segs = np.load(edges)
                axes[i][1].add_collection(LineCollection(segs, colors="black", linewidths=0.25))
                axes[i][1].set_title("mesh: %d edge pieces seen" % len(segs), fontsize=8)
            else:
                axes[i][1].set_title("(no mesh)", fontsize=8)
            dog = metric.read_image(str(st.image_path(tag + "_dog")))[:, :, 0]
            axes[i][2].imshow(dog, cmap="gray", vmin=-scale, vmax=scale)
            axes[i][2].set_title("centre-surround filtered brightness", fontsize=8)
            for ax in axes[i]:
                ax.set_xlim(0, w)
                ax.set_ylim(h, 0)
                ax.set_xticks([])
                ax.set_yticks([])
        fig.suptitle("%s: equal element counts (source Figs. 40-47)" % st.name, fontsize=10)
        fig.tight_layout()
        path = out / ("study_compare_%s.png" % st.name)
        fig.savefig(path, dpi=110)
        plt.close(fig)
        paths.append(path)
    return paths


def _refined(st):
    return next(r for r in st.rows if r["method"] == "refined")
