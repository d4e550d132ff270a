"""Crack maps from a run's cracks.csv at chosen creep times (paper Fig. 7 and 8).

Microcracks are broken bonds with ``creep_time_s <= t`` (-1 = broken during the ramp, so shown at
every t >= 0); macrocracks are bonds whose face is fully separated, ``macro_time_s <= t``, drawn
thicker. Each crack is the bond's face segment (x0_m, y0_m)-(x1_m, y1_m); files without these
columns get a segment one grain size long centred on (x_m, y_m) along the face, i.e. at
``face_normal_angle_deg`` + 90 degrees.

With the run's specimen (rebuilt by :func:`~grainfrac_yade.analysis.runparams.rebuild_specimen`)
the grains are drawn faintly under the cracks, coloured by mineral (paper Fig. 7/8 show them).
"""
from __future__ import annotations

import textwrap

import numpy as np
import pandas as pd
from matplotlib.collections import LineCollection
from matplotlib.lines import Line2D
from matplotlib.patches import Rectangle

from .plotting import CRACK_COLOURS, draw_cells, plt

MM = 1e3
SEGMENT_COLUMNS = ("x0_m", "y0_m", "x1_m", "y1_m")
MICRO_WIDTH, MACRO_WIDTH = 0.6, 2.0   # line widths [pt]
#: Crack colours; "kind" avoids the orange of k-feldspar in the grain map below.
COLOURS = {"mode": {"tensile": CRACK_COLOURS[1], "shear": CRACK_COLOURS[2]},
           "kind": {"inter": "#7b1fa2", "intra": "#00897b"}}
#: Opacity of the grain cells under the cracks.
GRAIN_ALPHA = 0.3
TITLES = {"mode": "tensile / shear", "kind": "inter- / intra-granular"}
DPI = 130
TITLE_CHARS = 120   # wrap long titles (variant labels) at this many characters


def has_segments(cracks: pd.DataFrame) -> bool:
    return all(c in cracks for c in SEGMENT_COLUMNS) and cracks[list(SEGMENT_COLUMNS)].notna().all().all()


def crack_segments(cracks: pd.DataFrame, grain_size: float) -> np.ndarray:
    """(c, 2, 2) segment end points [m]: recorded, or a grain-size segment along the face."""
    if has_segments(cracks):
        xy = cracks[list(SEGMENT_COLUMNS)].to_numpy(float)
        return xy.reshape(-1, 2, 2)
    along = np.radians(cracks["face_normal_angle_deg"].to_numpy(float) + 90.0)
    half = 0.5 * grain_size * np.column_stack([np.cos(along), np.sin(along)])
    centre = cracks[["x_m", "y_m"]].to_numpy(float)
    return np.stack([centre - half, centre + half], axis=1)


def cracks_at(cracks: pd.DataFrame, t: float):
    """(micro, macro) boolean masks of cracks present at creep time ``t`` [s]."""
    micro = cracks["creep_time_s"].to_numpy(float) <= t
    if "macro_time_s" in cracks:
        macro = pd.to_numeric(cracks["macro_time_s"], errors="coerce").to_numpy(float) <= t  # NaN -> False
    else:
        macro = np.zeros(len(cracks), bool)
    return micro, macro & micro


def crack_maps_figure(path, cracks: pd.DataFrame, times, labels, width: float, height: float,
                      grain_size: float, colour_by: str = "mode", title: str = "", specimen=None,
                      grain_alpha: float = GRAIN_ALPHA):
    """One panel per time: specimen outline, microcracks thin, macrocracks thick, coloured by
    ``colour_by`` ("mode": tensile/shear, "kind": inter/intra-granular). ``specimen`` (2D
    :class:`~grainfrac_yade.geometry.specimen.Specimen`): its cells are drawn under the cracks, coloured by
    mineral with opacity ``grain_alpha``; None: outline only."""
    seg = crack_segments(cracks, grain_size) * MM
    palette = COLOURS[colour_by]
    colours = np.array([palette.get(v, "k") for v in cracks[colour_by].astype(str)], dtype=object)
    n = len(times)
    panel_w = 2.4
    fig, axes = plt.subplots(1, n, figsize=(panel_w * n + 0.6, panel_w * height / width + 1.0), squeeze=False)
    mineral_handles = []
    for ax, t, lab in zip(axes[0], times, labels):
        if specimen is not None:
            mineral_handles = draw_cells(ax, specimen, alpha=grain_alpha)
            ax.set_ylabel("")
        micro, macro = cracks_at(cracks, t)
        for sel, lw in ((micro & ~macro, MICRO_WIDTH), (macro, MACRO_WIDTH)):
            if sel.any():
                ax.add_collection(LineCollection(seg[sel], colors=list(colours[sel]), linewidths=lw))
        ax.add_patch(Rectangle((0, 0), width * MM, height * MM, fill=False, ec="k", lw=1.0))
        ax.set_xlim(-0.02 * width * MM, 1.02 * width * MM)
        ax.set_ylim(-0.02 * height * MM, 1.02 * height * MM)
        ax.set_aspect("equal")
        ax.set_xlabel("x [mm]")
        ax.set_title(f"{lab}\n{int(micro.sum())} cracks, {int(macro.sum())} of them macro", fontsize=7)
    axes[0][0].set_ylabel("y [mm]")
    handles = [Line2D([], [], color=c, lw=1.2, label=k) for k, c in palette.items()]
    handles.append(Line2D([], [], color="k", lw=MICRO_WIDTH, label="crack (broken bond)"))
    macro_label = "macrocrack (crack on a fully separated face)" if "macro_time_s" in cracks else \
        "macrocrack times not recorded in cracks.csv"
    handles.append(Line2D([], [], color="k", lw=MACRO_WIDTH, label=macro_label))
    if not has_segments(cracks):
        handles.append(Line2D([], [], color="none", label="segments: grain size along the face (no end points)"))
    for h in mineral_handles:
        h.set_alpha(grain_alpha)
        h.set_label(f"grain: {h.get_label()}")
    handles += mineral_handles
    if specimen is None:
        handles.append(Line2D([], [], color="none", label="grains not drawn (see report)"))
    ncol = 4 if mineral_handles else 3
    rows = -(-len(handles) // ncol)
    bottom = min(0.35, (0.2 * rows + 0.08) / fig.get_figheight())   # legend band [fraction of the figure]
    fig.legend(handles=handles, loc="lower center", ncol=ncol, fontsize=7, frameon=False)
    fig.suptitle(textwrap.fill(f"{title} - coloured {TITLES[colour_by]} (paper Fig. 7/8)",
                               max(40, int(TITLE_CHARS * n / 4))), fontsize=9)
    fig.tight_layout(rect=(0, bottom, 1, 1))
    fig.savefig(path, dpi=DPI, bbox_inches="tight")
    plt.close(fig)
    return path
