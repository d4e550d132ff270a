"""Pictures of specimens and crack maps (matplotlib, Agg backend; no YADE)."""
from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection, PolyCollection  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402

#: Mineral colours close to the paper's Fig. 2a legend order.
MINERAL_COLOURS = {"biotite": "#3b3b3b", "k_feldspar": "#e8a07a", "quartz": "#d8d8e8", "plagioclase": "#f4ecc8"}
FALLBACK_COLOURS = plt.cm.tab10.colors
#: Crack colours: tension and shear (paper Fig. 8 uses green for microcracks).
CRACK_COLOURS = {1: "#1f77b4", 2: "#d62728"}
MM = 1e3  # m -> mm for axes


def mineral_colours(names) -> list:
    return [MINERAL_COLOURS.get(n, FALLBACK_COLOURS[k % 10]) for k, n in enumerate(names)]


def draw_cells(ax, specimen, alpha: float = 1.0):
    """Cells of a 2D specimen coloured by mineral (paper Fig. 2a)."""
    t = specimen.tessellation
    colours = mineral_colours(specimen.mineral_names)
    polys = [v * MM for v in t.cell_vertices]
    ax.add_collection(PolyCollection(polys, facecolors=[colours[m] for m in specimen.mineral],
                                     edgecolors="#777777", linewidths=0.2, alpha=alpha))
    ax.set_xlim(0, t.box[0] * MM)
    ax.set_ylim(0, t.box[1] * MM)
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    handles = [Patch(facecolor=c, edgecolor="k", label=n.replace("_", "-")) for n, c in
               zip(specimen.mineral_names, colours)]
    return handles


def specimen_figure(specimen, path, bonds=None, title=None):
    """Write a PNG of the specimen; with ``bonds`` ((b,2,2) segments [m], is_inter) draw the network."""
    if specimen.tessellation.dim != 2:
        return _specimen_figure_3d(specimen, path, title)
    t = specimen.tessellation
    aspect = t.box[1] / t.box[0]
    fig, ax = plt.subplots(figsize=(5.5, min(12, 4.5 * aspect)))
    handles = draw_cells(ax, specimen, alpha=0.55 if bonds is not None else 1.0)
    if bonds is not None:
        segments, is_inter = bonds
        ax.add_collection(LineCollection(segments * MM, colors=np.where(is_inter, "#b2182b", "#2166ac"),
                                         linewidths=0.4))
        handles += [Patch(color="#b2182b", label="inter-granular bond"),
                    Patch(color="#2166ac", label="intra-granular bond")]
    ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.08), ncol=3, fontsize=7)
    ax.set_title(title or f"{t.n_cells} cells, seed {specimen.seed}")
    fig.tight_layout()
    fig.savefig(path, dpi=150)
    plt.close(fig)
    return path


def _specimen_figure_3d(specimen, path, title):
    t = specimen.tessellation
    fig, ax = plt.subplots(figsize=(5, 5 * t.box[1] / t.box[0]))
    colours = mineral_colours(specimen.mineral_names)
    ax.scatter(t.cell_centroid[:, 0] * MM, t.cell_centroid[:, 1] * MM, c=[colours[m] for m in specimen.mineral],
               s=12, edgecolors="k", linewidths=0.2)
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.set_title(title or f"3D box: {t.n_cells} cells (centroids), seed {specimen.seed}")
    fig.tight_layout()
    fig.savefig(path, dpi=150)
    plt.close(fig)
    return path


def crack_map(specimen, path, segments, modes, title=None, macro=None, guides=None):
    """Crack map: broken-bond faces on the cell picture, tension and shear in two colours.

    ``segments`` (c, 2, 2) [m]; ``modes`` (c,) 1 = tension, 2 = shear;
    ``macro`` optional (c,) bool drawn thicker (fully separated faces);
    ``guides`` optional (g, 2, 2) [m] thin dashed lines (e.g. a band the analysis counts cracks in).
    """
    t = specimen.tessellation
    fig, ax = plt.subplots(figsize=(5.5, min(12, 4.5 * t.box[1] / t.box[0])))
    draw_cells(ax, specimen, alpha=0.35)
    if guides is not None and len(guides):
        ax.add_collection(LineCollection(np.asarray(guides) * MM, colors="#555555", linewidths=0.7,
                                         linestyles="dashed"))
    widths = np.full(len(modes), 0.9) if macro is None else np.where(macro, 2.2, 0.9)
    if len(modes):
        ax.add_collection(LineCollection(np.asarray(segments) * MM,
                                         colors=[CRACK_COLOURS.get(int(m), "k") for m in modes],
                                         linewidths=widths))
    n_t, n_s = int(np.sum(np.asarray(modes) == 1)), int(np.sum(np.asarray(modes) == 2))
    ax.legend(handles=[Patch(color=CRACK_COLOURS[1], label=f"tensile ({n_t})"),
                       Patch(color=CRACK_COLOURS[2], label=f"shear ({n_s})")],
              loc="upper center", ncol=2, fontsize=8,
              # below the x label: -0.08 of a tall specimen's axes, proportionally lower for squat ones (discs)
              bbox_to_anchor=(0.5, -0.08 * max(1.0, 2.0 * t.box[0] / t.box[1])))
    ax.set_title(title or "crack map")
    fig.tight_layout()
    fig.savefig(path, dpi=150)
    plt.close(fig)
    return path
