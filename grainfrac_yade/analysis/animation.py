"""Crack-growth animation of a creep run from its own files (no YADE): GIF (Pillow), MP4 (ffmpeg).

Frames at creep times spaced linearly from 0 to the end of the run (the lifetime of a failed
run), or logarithmically over :data:`LOG_TIME_DECADES` decades up to it.  Each frame: the grains
coloured by mineral (the specimen rebuilt from params.json and the seed, checked against the run's
bond count and crack positions), the cracks present at that time (``cracks.csv``: break time,
mode; ramp cracks from the start) coloured by mode, macrocracks (faces fully separated) thicker,
and a strain-time inset (``history.csv``) with a marker at the frame's time.  The same frames as
the crack maps of paper Figs. 7-8, in motion.
"""
from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import GrainfracError
from .runparams import rebuild_specimen

#: Frames of an animation by default: 4 s at the default rate.
DEFAULT_FRAMES = 60
#: Frames per second by default.
DEFAULT_FPS = 15
#: Logarithmic time: the first frame this many decades before the end of the run.
LOG_TIME_DECADES = 3
#: Frame size [inch] at :data:`DPI`: 840 x 640 pixels, even numbers as the MP4 (yuv420p) needs.
FIGSIZE, DPI = (8.4, 6.4), 100
#: GIF palette size (Pillow's adaptive palette).
GIF_COLOURS = 128
MICRO_WIDTH, MACRO_WIDTH = 0.8, 2.2   # crack line widths [pt]
MM = 1e3
#: Strain in percent, as the report's figures draw it.
PERCENT = 100.0
#: Output names in the run folder.
GIF_NAME, MP4_NAME, FRAME_NAME = "animation.gif", "animation.mp4", "animation_frame.png"


def frame_times(t_end: float, n: int, log_time: bool = False) -> np.ndarray:
    """(n,) creep times [s] of the frames: linear from 0 to ``t_end``, or geometric from
    ``t_end`` x 10^-LOG_TIME_DECADES to ``t_end``; one frame at ``t_end`` when n == 1."""
    if n < 1:
        raise GrainfracError(f"--frames {n}: an animation needs at least one frame; fix: e.g. --frames {DEFAULT_FRAMES}")
    if not (np.isfinite(t_end) and t_end >= 0):
        raise GrainfracError(f"end of the run {t_end!r} s is not a finite creep time >= 0; fix: animate a finished run")
    if n == 1:
        return np.array([float(t_end)])
    if log_time:
        if t_end <= 0:
            raise GrainfracError("the run ended at creep time 0 (failed on loading): there is no creep time to "
                                 "draw on a logarithmic axis; fix: drop --log-time")
        return np.geomspace(t_end * 10.0 ** -LOG_TIME_DECADES, t_end, n)
    return np.linspace(0.0, t_end, n)


def _read_run(folder: Path):
    """(run.json, summary.json or {}, cracks, history) of a creep run folder; one clear line if not one."""
    try:
        run = json.loads((folder / "run.json").read_text())
    except (OSError, ValueError):
        raise GrainfracError(f"{folder}: no run here (run.json missing or unreadable); fix: give the --out folder "
                             "of a creep run") from None
    if run.get("command") != "creep":
        raise GrainfracError(f"{folder}: holds a {run.get('command')!r} run; fix: animate a creep run folder "
                             "(UCS and Brazilian tests: open their vtk/*.pvd series in ParaView)")
    try:
        summary = json.loads((folder / "summary.json").read_text())
    except (OSError, ValueError):
        summary = {}   # unfinished run: up to its last history row
    for name, cols in (("history.csv", ("creep_time_s", "axial_strain")), ("cracks.csv", ("creep_time_s", "mode"))):
        if not (folder / name).is_file():
            raise GrainfracError(f"{folder / name}: missing; fix: animate a creep run folder (it writes {name})")
    hist = pd.read_csv(folder / "history.csv")
    cracks = pd.read_csv(folder / "cracks.csv")
    if "phase" in cracks:   # the ramp's cracks have no creep time: they are there from the first frame on
        from .crack_phases import RAMP_TIME
        cracks["creep_time_s"] = cracks["creep_time_s"].where(cracks["phase"] != "ramp", RAMP_TIME)
    for name, frame, cols in (("history.csv", hist, ("creep_time_s", "axial_strain")),
                              ("cracks.csv", cracks, ("creep_time_s", "mode"))):
        missing = [c for c in cols if c not in frame]
        if missing:
            raise GrainfracError(f"{folder / name}: lacks column(s) {', '.join(missing)}; fix: rerun the creep test "
                                 "with this code")
    if not len(hist):
        raise GrainfracError(f"{folder / 'history.csv'}: no rows; fix: animate a run that reached its creep load")
    return run, summary, cracks, hist


def _specimen(folder, run, summary, cracks):
    """(specimen or None, note): the run's grains rebuilt and verified, else the reason."""
    try:
        rebuilt = rebuild_specimen(folder, run.get("seed"), n_bonds=summary.get("n_bonds"), cracks=cracks)
    except GrainfracError as exc:
        return None, f"grains not drawn: {exc}"
    return rebuilt.specimen, rebuilt.note


def _segments(cracks: pd.DataFrame, grain_size: float) -> np.ndarray:
    from .crackmaps import crack_segments
    return crack_segments(cracks, grain_size)


def macro_legend(macro_time_s) -> str:
    """Legend of the thick crack lines: what they are, or that the run has none (a legend line the map never
    draws would mislead); ``macro_time_s``: each crack's separation time (NaN: never)."""
    t = np.asarray(macro_time_s, float)
    if not np.isfinite(t).any():
        return "macrocrack: none in this run (or times not recorded)"
    return "macrocrack (face fully separated): thick, in its mode's colour"


class _Renderer:
    """One matplotlib figure redrawn per frame: grains once, cracks and the marker per time."""

    def __init__(self, specimen, box, cracks, segments, hist, t_end, log_time, title):
        from matplotlib.collections import LineCollection
        from matplotlib.lines import Line2D
        from matplotlib.patches import Rectangle

        from .plotting import CRACK_COLOURS, draw_cells, plt
        self.plt = plt
        self.fig = plt.figure(figsize=FIGSIZE, dpi=DPI)
        ax = self.fig.add_axes((0.06, 0.08, 0.42, 0.84))
        handles = []
        if specimen is not None:
            handles = draw_cells(ax, specimen, alpha=0.55)
        ax.add_patch(Rectangle((0, 0), box[0] * MM, box[1] * MM, fill=False, ec="k", lw=1.0))
        ax.set_xlim(-0.02 * box[0] * MM, 1.02 * box[0] * MM)
        ax.set_ylim(-0.02 * box[1] * MM, 1.02 * box[1] * MM)
        ax.set_aspect("equal")
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("y [mm]")
        self.t_break = cracks["creep_time_s"].to_numpy(float)
        macro = pd.to_numeric(cracks["macro_time_s"], errors="coerce").to_numpy(float) if "macro_time_s" in cracks \
            else np.full(len(cracks), np.nan)
        self.t_macro = macro
        self.colours = np.array([CRACK_COLOURS[2] if m == "shear" else CRACK_COLOURS[1] for m in cracks["mode"]],
                                dtype=object)
        self.seg = segments * MM
        self.lines = LineCollection([], linewidths=MICRO_WIDTH)
        ax.add_collection(self.lines)
        handles = [Line2D([], [], color=CRACK_COLOURS[1], lw=1.5, label="tensile crack"),
                   Line2D([], [], color=CRACK_COLOURS[2], lw=1.5, label="shear crack"),
                   Line2D([], [], color=CRACK_COLOURS[1], lw=MACRO_WIDTH, label=macro_legend(macro))] + handles
        self.fig.legend(handles=handles, loc="upper left", bbox_to_anchor=(0.57, 0.36), ncol=2, fontsize=8,
                        frameon=False)
        inset = self.fig.add_axes((0.59, 0.47, 0.37, 0.38))
        t = hist["creep_time_s"].to_numpy(float)
        strain = hist["axial_strain"].to_numpy(float)
        self.t_hist, self.strain = t, strain
        if log_time:
            left = t_end * 10.0 ** -LOG_TIME_DECADES
            inset.set_xscale("log")   # rows before the axis starts (creep time 0) drawn at its left end
            inset.plot(np.maximum(t, left), strain * PERCENT, color="#444444", lw=1.2, drawstyle="steps-post")
            inset.set_xlim(left, t_end)
        else:
            inset.plot(t, strain * PERCENT, color="#444444", lw=1.2, drawstyle="steps-post")
            inset.set_xlim(0, t_end if t_end > 0 else 1.0)
        inset.set_xlabel("creep time [s]")
        inset.set_ylabel("axial strain [%]")
        inset.set_title("strain - time", fontsize=9)
        inset.grid(alpha=0.3)
        (self.marker,) = inset.plot([], [], "o", color="#d62728", ms=7, zorder=5)
        self.cursor = inset.axvline(np.nan, color="#d62728", lw=0.8, alpha=0.6)
        self.text = self.fig.text(0.59, 0.93, "", fontsize=10, va="top")
        self.fig.suptitle(title, fontsize=10, x=0.06, ha="left")

    def strain_at(self, time: float) -> float:
        """Axial strain of the last history row at or before ``time`` (the history steps at events)."""
        k = int(np.searchsorted(self.t_hist, time, side="right")) - 1
        return float(self.strain[max(k, 0)])

    def frame(self, time: float, t_end: float) -> np.ndarray:
        """(h, w, 3) uint8 image of the state at creep time ``time``."""
        present = self.t_break <= time
        macro = present & (self.t_macro <= time)
        self.lines.set_segments(list(self.seg[present]))
        self.lines.set_color(list(self.colours[present]))
        self.lines.set_linewidth(np.where(macro[present], MACRO_WIDTH, MICRO_WIDTH))
        strain = self.strain_at(time)
        self.marker.set_data([time], [strain * PERCENT])
        self.cursor.set_xdata([time, time])
        frac = time / t_end if t_end > 0 else 1.0
        self.text.set_text(f"creep time {time:.4g} s ({frac:.1%} of the run)\n"
                           f"{int(present.sum())} cracks, {int(macro.sum())} of them macro")
        self.fig.canvas.draw()
        return np.asarray(self.fig.canvas.buffer_rgba())[:, :, :3].copy()

    def close(self):
        self.plt.close(self.fig)


def write_gif(path, images: list, fps: float) -> Path:
    """Animated GIF of ``images`` ((h, w, 3) uint8) at ``fps`` frames per second, looping."""
    from PIL import Image
    frames = [Image.fromarray(im).quantize(colors=GIF_COLOURS, method=Image.Quantize.MEDIANCUT) for im in images]
    path = Path(path)
    tmp = path.with_name(path.stem + ".tmp.gif")
    frames[0].save(tmp, save_all=True, append_images=frames[1:], duration=int(round(1000 / fps)), loop=0,
                   optimize=False)
    tmp.replace(path)
    return path


def write_mp4(path, images: list, fps: float) -> Path | None:
    """H.264 MP4 of ``images`` through ffmpeg; None when ffmpeg is not installed."""
    ffmpeg = shutil.which("ffmpeg")
    if ffmpeg is None:
        return None
    path = Path(path)
    h, w = images[0].shape[:2]
    tmp = path.with_name(path.stem + ".tmp.mp4")
    cmd = [ffmpeg, "-y", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgb24", "-s", f"{w}x{h}",
           "-r", f"{fps:g}", "-i", "-", "-c:v", "libx264", "-pix_fmt", "yuv420p", "-movflags", "+faststart", str(tmp)]
    proc = subprocess.run(cmd, input=b"".join(im.tobytes() for im in images), capture_output=True)
    if proc.returncode != 0:
        raise GrainfracError(f"{path}: ffmpeg failed ({proc.stderr.decode(errors='replace').strip()[:200]}); fix: "
                             "check the ffmpeg installation (apt-get install ffmpeg) or use the GIF")
    tmp.replace(path)
    return path


def animate_run(folder, log_time: bool = False, fps: float = DEFAULT_FPS, frames: int = DEFAULT_FRAMES,
                mp4: bool = True) -> dict:
    """Write ``animation.gif`` (and ``animation.mp4`` where ffmpeg exists, unless ``mp4`` is False)
    and ``animation_frame.png`` (the last frame) into the creep run ``folder``; returns what was written."""
    folder = Path(folder)
    if not (np.isfinite(fps) and fps > 0):
        raise GrainfracError(f"--fps {fps}: frames per second must be > 0; fix: e.g. --fps {DEFAULT_FPS}")
    run, summary, cracks, hist = _read_run(folder)
    t_end = summary.get("lifetime_s") or summary.get("creep_time_end_s") or float(hist["creep_time_s"].iloc[-1])
    times = frame_times(float(t_end), int(frames), log_time)
    specimen, note = _specimen(folder, run, summary, cracks)
    params = json.loads((folder / "params.json").read_text()) if (folder / "params.json").is_file() else {}
    spec = params.get("specimen", {})
    if specimen is not None:
        box = specimen.tessellation.box
    elif "width" in spec and "height" in spec:
        box = (float(spec["width"]), float(spec["height"]))
    else:
        raise GrainfracError(f"{folder / 'params.json'}: lacks specimen.width/height; fix: animate a run folder "
                             "written by this code")
    grain = float(spec.get("grain_size", 0.1 * min(box[0], box[1])))
    stress = summary.get("stress_pa")
    outcome = (f"lifetime {summary['lifetime_s']:.4g} s" if summary.get("lifetime_s") else
               f"not failed by {float(t_end):.4g} s" if summary else "unfinished run")
    title = (f"{folder.name}: creep at {stress / 1e6:.0f} MPa, {outcome}" if stress else f"{folder.name}: {outcome}")
    title += ", log time" if log_time else ""
    r = _Renderer(specimen, box, cracks, _segments(cracks, grain), hist, float(t_end), log_time, title)
    try:
        images = [r.frame(float(t), float(t_end)) for t in times]
    finally:
        r.close()
    from PIL import Image
    out = {"gif": write_gif(folder / GIF_NAME, images, fps), "frames": len(images), "grains": note,
           "times_s": [float(t) for t in times]}
    Image.fromarray(images[-1]).save(folder / FRAME_NAME)
    out["frame_png"] = folder / FRAME_NAME
    out["mp4"] = write_mp4(folder / MP4_NAME, images, fps) if mp4 else None
    return out
