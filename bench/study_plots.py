"""The study's plots (matplotlib, PNG): error against elements, time and vertices
(Figures 48-49 of the source, for both references and both metrics, with the
Cycles bake where it has the same axis) and, beside them, the signed exposure
error against the path-traced reference; and elements against time with the
least-squares line of Section 7.3.4 (Figures 38-39)."""

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402
import numpy as np  # noqa: E402

import curves  # noqa: E402
import study_config  # noqa: E402

COLOURS = {"standard": "tab:blue", "perceptual": "tab:orange", "gradient": "tab:green", "noticeable": "tab:red"}
METRICS = (("dog_refined", "DoG error vs refined radiosity"), ("rms_refined", "plain RMS vs refined radiosity"),
           ("dog_cycles", "DoG error vs Cycles path traced"), ("rms_cycles", "plain RMS vs Cycles path traced"))
# Signed, so on a linear axis beside the error metrics (which remove or dilute brightness).
EXPOSURE = ("exposure_cycles", "exposure error vs Cycles (signed)")
BAKE_MARKERS = "svD^P*"


def radiosity_rows(study, oracle):
    return [r for r in study.rows if r["method"] == "radiosity" and r["oracle"] == oracle]


def _error_grid(studies, x_key, x_label, out_path, with_bake, title):
    columns = METRICS + (EXPOSURE,)
    fig, axes = plt.subplots(len(studies), len(columns), figsize=(4.2 * len(columns), 3.4 * len(studies)),
                             squeeze=False)
    for i, st in enumerate(studies):
        for j, (metric, label) in enumerate(columns):
            ax = axes[i][j]
            for oracle in study_config.ORACLES:
                rows = sorted(radiosity_rows(st, oracle), key=lambda r: r[x_key])
                if rows:
                    ax.plot([r[x_key] for r in rows], [r[metric] for r in rows], "o-", ms=3.5, lw=1,
                            color=COLOURS[oracle], label=oracle)
            if with_bake and st.bake_rows:
                for k, samples in enumerate(sorted({b["samples"] for b in st.bake_rows})):
                    rows = sorted((b for b in st.bake_rows if b["samples"] == samples), key=lambda b: b[x_key])
                    ax.plot([b[x_key] for b in rows], [b[metric] for b in rows], "--", marker=BAKE_MARKERS[k % 6],
                            ms=4, lw=1, color=str(0.15 + 0.2 * k), label="Cycles bake %d spp" % samples)
            kind = metric.split("_")[0]
            if metric.endswith("cycles") and st.noise:
                noise = st.noise[kind]
                if metric == EXPOSURE[0]:
                    ax.axhline(0.0, color="grey", lw=0.8)
                    ax.axhspan(-noise, noise, color="red", alpha=0.15, label="reference noise")
                else:
                    ax.axhline(noise, color="red", lw=0.8, ls=":", label="reference noise")
                ax.axhline(st.refined_vs_cycles[kind], color="black", lw=0.8, ls="-.",
                           label="refined radiosity")
            ax.set_xscale("log")
            if metric == EXPOSURE[0]:
                ax.yaxis.set_major_formatter(matplotlib.ticker.PercentFormatter(1.0))
            else:
                ax.set_yscale("log")
            ax.grid(True, which="both", alpha=0.3)
            ax.set_title("%s: %s" % (st.name, label), fontsize=9)
            ax.set_xlabel(x_label, fontsize=8)
            ax.tick_params(labelsize=7)
            if j == 0:
                ax.set_ylabel("error (display brightness, 0-1)", fontsize=8)
            if j == len(columns) - 1:
                ax.set_ylabel("mean luminance / Cycles' - 1", fontsize=8)
            if i == 0 and j == len(METRICS) - 1:
                ax.legend(fontsize=6, loc="best")
    fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    fig.savefig(out_path, dpi=90)
    plt.close(fig)
    return out_path


def elements_vs_time(studies, out_path):
    fig, axes = plt.subplots(1, len(studies), figsize=(4.6 * len(studies), 4.0), squeeze=False)
    for ax, st in zip(axes[0], studies):
        for oracle in study_config.ORACLES:
            rows = radiosity_rows(st, oracle)
            if not rows:
                continue
            x = np.array([r["leaves"] for r in rows], dtype=float)
            y = np.array([r["seconds"] for r in rows])
            a, b, r, n = curves.least_squares(x, y)
            ax.plot(x, y, "o", ms=4, color=COLOURS[oracle],
                    label="%s: a=%.3g b=%.3g r=%.3f" % (oracle, a, b, r))
            xs = np.linspace(0, x.max() * 1.05, 50)
            ax.plot(xs, a + b * xs, "-", lw=0.8, color=COLOURS[oracle])
        ax.set_xlabel("leaf elements", fontsize=8)
        ax.set_ylabel("solve time (s)", fontsize=8)
        ax.set_title("%s: time = a + b x elements" % st.name, fontsize=9)
        ax.grid(True, alpha=0.3)
        ax.set_xlim(left=0)
        ax.set_ylim(bottom=0)
        ax.legend(fontsize=7)
        ax.tick_params(labelsize=7)
    fig.tight_layout()
    fig.savefig(out_path, dpi=90)
    plt.close(fig)
    return out_path


def plot_all(studies, out):
    return [
        _error_grid(studies, "leaves", "leaf elements", out / "study_error_vs_elements.png", False,
                    "Error against output size (source Fig. 48); error falls to the right"),
        _error_grid(studies, "seconds", "time (s): radiosity solve / Cycles bake", out / "study_error_vs_time.png",
                    True, "Error against time (source Fig. 49), with Cycles bakes"),
        _error_grid(studies, "vertices", "vertices of the shown mesh", out / "study_error_vs_vertices.png", True,
                    "Error against vertices (radiosity output and uniformly subdivided Cycles bake)"),
        elements_vs_time(studies, out / "study_elements_vs_time.png"),
    ]
