"""``demo``: the main job, a small lifetime study end to end.

1. specimen summary and picture (seed 1);
2. UCS of the small specimen for each seed (yade-batch, ``yade_scripts/ucs.py``): the mean
   is the UCS the driving-stress ratios refer to, as a lab refers to its mean UCS;
3. creep to failure at each ratio and seed (yade-batch, ``yade_scripts/creep.py``);
4. the analysis report of the creep runs (``analyze``).

About 3-4 min on 2 cores with the defaults (measured in the notes); every run writes a new
``results/demo_<date-time>/`` unless ``--out`` is given.
"""
from __future__ import annotations

import json
import os
import time
from pathlib import Path

from ..errors import GrainfracError
from ..params import flat_values, require_plane
from ..runs.batchrun import read_table_rows, row_outcomes, run_batch, write_table
from ._args import float_list_type, seed_list_type
from ._outcome import outcome

#: Demo defaults: a 10 x 20 mm specimen (about 200 cells; a creep run takes 15-40 s on one core).
DEMO_WIDTH_M, DEMO_HEIGHT_M = 10e-3, 20e-3
DEMO_SEEDS = (1, 2)
DEMO_RATIOS = (0.7, 0.8, 0.9)


def register(sub, common):
    p = sub.add_parser("demo", help="main job: small lifetime study (specimen, UCS, creep at 3 ratios, report)")
    common(p, geometry=False)
    p.add_argument("--ratios", type=float_list_type, default=list(DEMO_RATIOS), help="driving-stress ratios, e.g. 0.7,0.8,0.9")
    p.add_argument("--seeds", type=seed_list_type, default=list(DEMO_SEEDS), help="specimen seeds, e.g. 1,2")
    p.add_argument("--width", type=float, default=DEMO_WIDTH_M, help="specimen width [m]")
    p.add_argument("--height", type=float, default=DEMO_HEIGHT_M, help="specimen height [m]")
    p.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="runs at a time (default: cores)")
    p.set_defaults(func=cmd_demo, with_params=True)


def _say(t0, msg):
    print(f"[demo {time.time() - t0:6.0f} s] {msg}", flush=True)


def cmd_demo(args, params) -> int:
    from ._specimen import run_specimen
    t0 = time.time()
    repo = Path(__file__).resolve().parents[2]
    out = Path(args.out or time.strftime("results/demo_%Y%m%d-%H%M%S")).resolve()  # a new folder each run
    if out.exists() and any(out.iterdir()) and not args.overwrite:
        raise GrainfracError(f"{out} already holds results; fix: choose another --out or add --overwrite")
    require_plane(params, "demo")   # params: loaded (--params/--set validated) before anything runs
    check_demo_arguments(args, params)
    extra = flat_values(args.params, args.resolved_overrides)   # --params, --set and --width/--height
    _say(t0, f"specimen {args.width * 1e3:.0f} x {args.height * 1e3:.0f} mm, seeds {args.seeds}, "
             f"ratios {args.ratios}, {args.jobs} jobs -> {out}")
    rec = run_specimen(params, args.seeds[0], out / "specimen", overwrite=args.overwrite)
    _say(t0, f"specimen: {rec['n_cells']} cells, {rec['n_bonds']} bonds")

    ucs_rows = [dict(extra, seed=s, out=str(out / "ucs" / f"seed{s}")) for s in args.seeds]
    table = write_table(out / "ucs.table", ucs_rows, "UCS rows of the demo")
    run_batch(table, repo / "yade_scripts" / "ucs.py", args.jobs, out / "logs_ucs",
              watch=[r["out"] for r in ucs_rows], repo=repo,
              progress=lambda w: _say(t0, f"UCS {w.name}: {_ucs_line(_read(w))}"))
    failed = _failed_rows(table, out / "logs_ucs")
    ucs = [_read(Path(r["out"])).get("ucs_pa") for r in ucs_rows if (Path(r["out"]) / "summary.json").exists()]
    ucs = [u for u in ucs if u is not None]   # a numerical failure has no UCS
    if not ucs:
        raise GrainfracError(f"no UCS run finished; see the logs in {out / 'logs_ucs'}")
    ucs_mean = sum(ucs) / len(ucs)
    _say(t0, f"mean UCS {ucs_mean / 1e6:.1f} MPa ({len(ucs)} seeds): the reference of the ratios")

    creep_rows = [dict(extra, ratio=r, ucs=ucs_mean, seed=s, out=str(out / "creep" / f"ratio{r:g}_seed{s}"))
                  for r in args.ratios for s in args.seeds]
    table = write_table(out / "creep.table", creep_rows, f"creep rows of the demo; ucs = mean of {len(ucs)} seeds")
    run_batch(table, repo / "yade_scripts" / "creep.py", args.jobs, out / "logs_creep",
              watch=[r["out"] for r in creep_rows], repo=repo, progress=lambda w: _say(t0, _creep_line(w)))
    failed += _failed_rows(table, out / "logs_creep")

    from ..analysis.study import analyze_study
    report = analyze_study(out / "creep")
    if failed:
        _say(t0, f"report of the finished runs: {report}")
        for row in failed:
            _say(t0, str(row))   # "line N: FAILED: ..." or "line N: numerical failure: ..."
        _say(t0, f"{len(failed)} rows failed or ended as a numerical failure (listed above; their logs say why)")
        return 1
    _say(t0, f"done. Report: {report}")
    return 0


def check_demo_arguments(args, params) -> None:
    """Refuse, before anything runs, what would make rows fail: ratios outside (0, 1), negative seeds, no
    seeds or ratios, fewer than one job (one line each)."""
    bad = [r for r in args.ratios if not 0 < r < 1]
    if bad or not args.ratios:
        raise GrainfracError(f"--ratios {','.join(f'{r:g}' for r in args.ratios) or '(none)'}: a driving-stress "
                             "ratio must lie in (0, 1) (at 1 or above the specimen fails on loading); fix: e.g. "
                             "--ratios 0.7,0.8,0.9")
    if not args.seeds or any(s < 0 for s in args.seeds):
        raise GrainfracError(f"--seeds {args.seeds}: fix: whole numbers >= 0, e.g. --seeds 1,2")
    if args.jobs < 1:
        raise GrainfracError(f"--jobs {args.jobs}: fix: at least 1")


def _failed_rows(table, log_dir) -> list:
    """The rows of ``table`` run into ``log_dir`` that did not finish a run with a result (:func:`row_outcomes`: a
    numerical failure is not ok)."""
    _, rows, _ = read_table_rows(table)
    return [o for o in row_outcomes(table, log_dir, list(rows)) if not o.ok]


def _read(folder: Path) -> dict:
    return json.loads((folder / "summary.json").read_text())


def _ucs_line(summary: dict) -> str:
    if summary.get("ucs_pa") is None:
        return f"no result ({summary.get('end_reason', 'no UCS')})"
    return f"{summary['ucs_pa'] / 1e6:.1f} MPa"


def _creep_line(folder: Path) -> str:
    s = _read(folder)
    return f"creep {folder.name}: {s['stress_pa'] / 1e6:.0f} MPa, {outcome(s)}, {s['n_events']} events"
