"""Joint calibration of the contact levers to the lab's bands (grainfrac_yade.analysis.lab_fit): docs/studies/lab_calibration.md.

Four parts, run in this order; each reads what the one before wrote and writes plain files:

* ``design``: the design points (``lab_fit.design``), each a 10 x 20 mm UCS test and a 10 mm Brazilian
  test per seed, one row per test into CSV (units in the column names).  Rows already in the CSV are
  skipped, so a stopped run goes on where it was (``--n`` and ``--design-seed`` must stay the same).
* ``backfill``: columns rows of older code lack, read from their run folders.
* ``reseat``: the (point, seed) pairs whose UCS test or disc stopped in its seating, run again with the end
  criteria's minimum strain (:data:`STOP_KEYS`); their old rows are kept in ``<csv>.seating.csv``.
* ``fit``: the linear response surface and its least-squares optimum: JSON with the candidate's keys.
* ``best``: the alternative to ``fit`` once a fit's candidate has missed: the design point whose *measured*
  seed means lie nearest the lab (smallest sum of squared residuals in lab spreads, every observable
  measured), as JSON of the same form, its design rows copied into the verification CSV (``--verify-csv``).
* ``verify``: the candidate on more seeds (same specimens): rows into a CSV of their own.
* ``preset``: ``params/presets/ldb_lab.toml``, the fem preset with the candidate's keys and the verified
  measurements and residuals beside each target.

    OMP_NUM_THREADS=1 /usr/bin/python3 -m studies.lab_calibration design --n 14 --seeds 1 2 \\
        --csv docs/studies/lab_calibration_design.csv --out results/lab_calibration
    /usr/bin/python3 -m studies.lab_calibration fit --csv docs/studies/lab_calibration_design.csv \\
        --json docs/studies/lab_calibration_fit.json
    OMP_NUM_THREADS=1 /usr/bin/python3 -m studies.lab_calibration verify --json docs/studies/lab_calibration_fit.json \\
        --seeds 1 2 3 --csv docs/studies/lab_calibration_verify.csv --out results/lab_calibration
    /usr/bin/python3 -m studies.lab_calibration preset --json docs/studies/lab_calibration_fit.json \\
        --csv docs/studies/lab_calibration_verify.csv
    /usr/bin/python3 -m studies.lab_calibration best --csv docs/studies/lab_calibration_design.csv \\
        --json docs/studies/lab_calibration_best.json --verify-csv docs/studies/lab_calibration_verify_best.csv
"""
from __future__ import annotations

import argparse
import csv
import json
from pathlib import Path

import numpy as np

from grainfrac_yade.api import lab_fit
from studies.lab_bands import LEVER_FIELDS, measure

ROOT = Path(__file__).resolve().parents[1]
#: The base model: finite-element cells, Tables 1 and 2 as printed.
BASE_PARAMS = [str(ROOT / "params" / "presets" / "fem_coarse.toml")]
#: Specimens: the 10 x 20 mm UCS specimen of the fem studies and the smallest disc whose sigma_t the
#: lever study read (10 mm, about 100 cells) [m].
UCS_SIZE = (10e-3, 20e-3)
DISC_DIAMETER = 10e-3
PRESET = ROOT / "params" / "presets" / "ldb_lab.toml"
POINT_FIELDS = ("point", *(f"u_{v.name}" for v in lab_fit.FIT_VARIABLES), *LEVER_FIELDS[1:], "broken_total",
                "crack_initiation_volumetric_pa")
#: Grain size of the design's specimens [m] (specimen.grain_size as shipped).
GRAIN_SIZE = 1e-3
#: A Brazilian peak is a split only if at least as many bonds broke by the test's end as grains lie on
#: the loaded diameter (D / grain size): a crack across the disc breaks at least one face per grain.
#: Below it the "peak" is a seating transient in which a near-zero-strength face broke (Weibull m near
#: 1.7: measured 1 bond broken, 1.3 MPa, 108 DEM steps) and the end criterion took the ringing for the
#: post-peak branch; such a sigma_t is left out of the fit.
MIN_SPLIT_BREAKS = round(DISC_DIAMETER / GRAIN_SIZE)
#: The end criteria's minimum strain (``ucs.stop_min_strain``, ``brazilian.stop_min_strain``) [1]: past the start
#: transient (the seating stops ended at 2e-6 to 4e-5 of strain) and well before any real peak of the design
#: (UCS at 3.3e-3 of axial strain or more, splits at 7.9e-4 of diametral strain or more), so that it moves
#: only the seating stops.
STOP_KEYS = ("ucs.stop_min_strain=2e-4", "brazilian.stop_min_strain=2e-4")


def _rows(path: Path) -> list:
    return list(csv.DictReader(Path(path).open())) if Path(path).exists() else []


def _append(path: Path, rows):
    path = Path(path)
    new = not path.exists()
    with path.open("a", newline="") as f:
        w = csv.DictWriter(f, fieldnames=POINT_FIELDS)
        if new:
            w.writeheader()
        w.writerows(rows)


def run_point(point: int, u, seeds, csv_path: Path, out: Path, extra=()):
    """Run point ``u`` on ``seeds`` unless its rows are in ``csv_path``; rows appended as each seed ends."""
    done = {(int(r["point"]), int(r["seed"])) for r in _rows(csv_path)}
    for seed in seeds:
        if (point, seed) in done:
            continue
        rows = measure([*BASE_PARAMS, *extra], [*lab_fit.overrides(u), *STOP_KEYS], seed,
                       Path(out) / f"point{point}_seed{seed}",
                       ucs_size=UCS_SIZE, disc_diameter=DISC_DIAMETER)
        coords = {f"u_{v.name}": float(x) for v, x in zip(lab_fit.FIT_VARIABLES, u)}
        _append(csv_path, [{"point": point, **coords, **r} for r in rows])
        print(f"point {point} seed {seed}: " + ", ".join(
            f"{r['test']} {(r.get('ucs_pa') or r.get('tensile_strength_pa') or float('nan')) / 1e6:.1f} MPa "
            f"({r['cpu_s']:.0f} s)" for r in rows), flush=True)


def _write(path: Path, rows):
    """Rewrite ``path`` with ``rows`` (written beside it, then renamed: a stop never leaves half a file)."""
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    with tmp.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=POINT_FIELDS)
        w.writeheader()
        w.writerows({k: r.get(k, "") for k in POINT_FIELDS} for r in rows)
    tmp.replace(path)


def _missing(r, key) -> bool:
    return r.get(key) in (None, "", "None", "nan")


def backfill(csv_path: Path, out: Path) -> int:
    """Fill the columns rows written by older code lack (``broken_total`` of a disc, the volumetric CI of a
    UCS test) from their run folders ``out``/point{P}_seed{S}_{test}/; returns the number filled."""
    from studies.lab_bands import volumetric_crack_initiation
    rows, filled = _rows(csv_path), 0
    for r in rows:
        folder = Path(out) / f"point{r['point']}_seed{r['seed']}_{r['test']}"
        if not (folder / "summary.json").exists():
            continue
        s = json.loads((folder / "summary.json").read_text())
        if r["test"] == "brazilian" and _missing(r, "broken_total"):
            r["broken_total"], filled = s["broken_total"], filled + 1
        if r["test"] == "ucs" and _missing(r, "crack_initiation_volumetric_pa") and s.get("young_pa"):
            r["crack_initiation_volumetric_pa"], filled = volumetric_crack_initiation(folder, s), filled + 1
    if filled:
        _write(csv_path, rows)
    return filled


def seating_stops(rows) -> set:
    """(point, seed) pairs with a test that stopped in its seating: a UCS test without a fitted modulus, or a
    disc with fewer than :data:`MIN_SPLIT_BREAKS` bonds broken."""
    out = set()
    for r in rows:
        if ((r["test"] == "ucs" and _missing(r, "young_pa"))
                or (r["test"] == "brazilian" and not _missing(r, "broken_total")
                    and float(r["broken_total"]) < MIN_SPLIT_BREAKS)):
            out.add((int(r["point"]), int(r["seed"])))
    return out


def reseat(csv_path: Path, out: Path, n: int, design_seed: int) -> list:
    """Run the design's (point, seed) pairs that stopped in their seating again with :data:`STOP_KEYS`.
    Their old rows move to ``<csv>.seating.csv`` (kept, not lost) before the new ones are appended."""
    csv_path = Path(csv_path)
    rows = _rows(csv_path)
    pairs = sorted(seating_stops(rows))
    if not pairs:
        return []
    keep = [r for r in rows if (int(r["point"]), int(r["seed"])) not in pairs]
    moved = [r for r in rows if (int(r["point"]), int(r["seed"])) in pairs]
    side = csv_path.with_name(csv_path.name + ".seating.csv")
    old = _rows(side)
    _write(side, old + moved)
    _write(csv_path, keep)
    pts = lab_fit.design(n, design_seed)
    for point, seed in pairs:
        run_point(point, pts[point], [seed], csv_path, out)
    return pairs


def _mean(values) -> float:
    v = np.asarray(values, dtype=float)
    return float(v[np.isfinite(v)].mean()) if np.isfinite(v).any() else np.nan


def point_means(rows) -> tuple:
    """(points, u (m, 5), measured seed means (m, 5) in Pa and 1: UCS, E, sigma_t, CI/UCS, CD/UCS).

    CI is read as the lab reads it, from the crack volumetric strain (Martin & Chandler 1994), not from
    the first 2 % of the bond breaks (the UCS summary's ``crack_initiation_pa``): the two differ by a
    factor of 2-15 on fem cells with weak faces (docs/studies/lab_calibration.md)."""
    def val(r, k):
        return float(r[k]) if r.get(k) not in (None, "", "None") else np.nan

    def split(r):
        return val(r, "tensile_strength_pa") if val(r, "broken_total") >= MIN_SPLIT_BREAKS else np.nan
    by_point = {}
    for r in rows:
        by_point.setdefault(int(r["point"]), []).append(r)
    points, us, ys = [], [], []
    for p, rs in sorted(by_point.items()):
        # a UCS test with no fitted modulus stopped in its seating (weak faces broke in the ringing and the
        # end criterion took the drop for the post-peak branch: measured 11.5 MPa after 1,032 DEM steps):
        # no UCS, E, CI or CD
        ucs = [r for r in rs if r["test"] == "ucs" and np.isfinite(val(r, "young_pa"))]
        bz = [r for r in rs if r["test"] == "brazilian"]
        points.append(p)
        us.append([float(rs[0][f"u_{v.name}"]) for v in lab_fit.FIT_VARIABLES])
        ys.append([_mean([val(r, "ucs_pa") for r in ucs]), _mean([val(r, "young_pa") for r in ucs]),
                   _mean([split(r) for r in bz]),
                   _mean([val(r, "crack_initiation_volumetric_pa") / val(r, "ucs_pa") for r in ucs]),
                   _mean([val(r, "cd_over_ucs") for r in ucs])])
    return points, np.array(us), np.array(ys)


def fit(csv_path: Path, ucs_target=None, squared=()) -> dict:
    """The surface over the design's seed means and its optimum; ``squared``: names of the variables with a
    square term (() : linear)."""
    points, u, y = point_means(_rows(csv_path))
    targets = lab_fit.lab_targets(ucs_value=ucs_target)
    names = [v.name for v in lab_fit.FIT_VARIABLES]
    surface = lab_fit.fit_surrogate(u, lab_fit.scaled(y), [names.index(n) for n in squared])
    best, predicted = lab_fit.solve(surface, targets)
    return {
        "design_csv": str(csv_path), "n_points": len(points), "method": FIT_METHOD,
        "targets": dict(zip(targets.names, targets.value.tolist())),
        "target_spreads": dict(zip(targets.names, targets.spread.tolist())),
        "target_sources": dict(zip(targets.names, targets.sources)),
        "surface_r2": dict(zip(targets.names, surface.r2.tolist())),
        "surface_residual_sd": dict(zip(targets.names, surface.residual_sd.tolist())),
        "surface_slope_per_unit": {o: dict(zip(names, row)) for o, row in zip(targets.names, surface.slope.tolist())},
        "surface_square_terms": {o: dict(zip(squared, row)) for o, row in zip(targets.names, surface.curvature.tolist())},
        "candidate_u": dict(zip(names, best.tolist())),
        "candidate_overrides": lab_fit.overrides(best),
        "predicted": dict(zip(targets.names, lab_fit.unscaled(surface.predict(best)).tolist())),
        "predicted_weighted_residuals": dict(zip(targets.names, predicted.tolist())),
    }


#: How a result's candidate was chosen, as the preset's header says it (``fit`` and ``best``).
FIT_METHOD = "the least-squares optimum of the response surface fitted to"
BEST_METHOD = "design point {point}, the one whose measured seed means lie nearest the lab's targets, of"


def measured_cost(rows, targets) -> tuple:
    """(points, u (m, 5), seed means (m, 5), weighted residuals (m, 5), sum of their squares (m,)): each
    design point's measured distance from ``targets``; a point with an observable not measured has cost NaN."""
    points, u, y = point_means(rows)
    resid = lab_fit.weighted_residuals(lab_fit.scaled(y), targets)
    cost = np.where(np.isfinite(resid).all(axis=1), np.nansum(resid ** 2, axis=1), np.nan)
    return points, u, y, resid, cost


def best_point(rows, csv_path: Path) -> dict:
    """The design point of ``rows`` (read from ``csv_path``) nearest the lab as measured
    (:func:`measured_cost`), as a result of the form of :func:`fit`: its keys, and its design seed means as
    what is expected before the check."""
    targets = lab_fit.lab_targets()
    points, us, y, resid, cost = measured_cost(rows, targets)
    if not np.isfinite(cost).any():
        raise SystemExit(f"{csv_path}: no design point has all five observables measured; fix: run the design first")
    k = int(np.nanargmin(cost))
    u = us[k]
    return {
        "design_csv": str(csv_path), "n_points": len(points), "design_point": points[k],
        "method": BEST_METHOD.format(point=points[k]),
        "targets": dict(zip(targets.names, targets.value.tolist())),
        "target_spreads": dict(zip(targets.names, targets.spread.tolist())),
        "candidate_u": dict(zip((v.name for v in lab_fit.FIT_VARIABLES), u.tolist())),
        "candidate_overrides": lab_fit.overrides(u),
        "predicted": dict(zip(targets.names, y[k].tolist())),
        "predicted_weighted_residuals": dict(zip(targets.names, resid[k].tolist())),
        "measured_cost_per_point": {str(p): (None if not np.isfinite(c) else float(c)) for p, c in zip(points, cost)},
    }


def preset_text(result: dict, verify_rows, base_preset: Path = Path(BASE_PARAMS[0]), design_csv=None) -> str:
    """The preset: a header with the verified residuals, the base preset's model keys ([resolution],
    [numerics]), a [calibration] section with the candidate's keys and the verified mean UCS, and the end
    criteria's minimum strains the verification ran with (:data:`STOP_KEYS`). ``design_csv``: the design's
    file as the header names it (default: the path the fit read)."""
    import tomllib
    targets = lab_fit.lab_targets()
    _, _, measured = point_means(verify_rows)
    per_seed = {}
    for r in verify_rows:
        per_seed.setdefault(r["test"], []).append(r)
    seeds = sorted({int(r["seed"]) for r in verify_rows})
    mean = measured[0]
    y_scaled = lab_fit.scaled(mean[None, :])[0]
    resid = lab_fit.weighted_residuals(y_scaled, targets)
    units = {"ucs": (1e6, "MPa"), "young": (1e9, "GPa"), "tensile_strength": (1e6, "MPa"),
             "ci_over_ucs": (1.0, ""), "cd_over_ucs": (1.0, "")}
    lines = ["# Finite-element grains calibrated jointly to Lac du Bonnet granite's lab bands (docs/studies/lab_calibration.md):",
             "# UCS, E, Brazilian tensile strength, CI/UCS and CD/UCS, by five contact levers ([calibration] below),",
             f"# written by  python3 -m studies.lab_calibration preset  from {result['method']}",
             f"#   {design_csv or result['design_csv']} ({result['n_points']} design points)",
             f"# and its verification on seeds {seeds} (10 x 20 mm UCS at the preset's 0.5 /s, 10 mm Brazilian disc).",
             "# Targets: params/reference/ldb_lab_properties.csv (the lab's UCS 200 MPa, not the paper's simulated 234.5 MPa:",
             "# every other target is a lab property of one granite). Use with --params params/presets/ldb_lab.toml.",
             "#",
             "# target             lab value +- spread       verified mean (seeds)     residual [lab spreads]   expected before the check"]
    for k, name in enumerate(targets.names):
        f, unit = units[name]
        lines.append(f"#   {name:18s} {targets.value[k] / f:8.3g} +- {targets.spread[k] / f:<7.3g} {unit:4s} "
                     f"{mean[k] / f:9.4g} {unit:4s}            {resid[k]:+6.2f}                 "
                     f"{result['predicted'][name] / f:.4g}")
    lines += ["#   (tensile_strength from 10 mm discs, the design's; larger discs read it lower: the disc-size section",
              "#   of docs/studies/lab_calibration.md)"]
    base = Path(base_preset).read_text()
    model = base[base.index("[resolution]"):base.index("[calibration]")].rstrip()
    cal = dict(o.split("=") for o in result["candidate_overrides"])
    doc = {v.key: v for v in lab_fit.FIT_VARIABLES}
    lines += ["", "# the model's keys, as " + str(Path(base_preset).relative_to(ROOT)), model, "", "[calibration]"]
    for key, value in cal.items():
        name = key.split(".", 1)[1]
        lines.append(f"{name} = {float(value)!r}    # 1, calibrated: {doc[key].doc}")
    lines += ["stiffness_scale = 1.0    # 1, not fitted: Table 2 as printed",
              f"reference_ucs = {mean[0]:.6g}    # Pa, the verified mean UCS above; what a driving-stress ratio refers to"]
    sections = {}
    for key, value in (k.split("=") for k in STOP_KEYS):
        section, name = key.split(".")
        sections.setdefault(section, []).append(f"{name} = {float(value)!r}    # 1, as the verification ran: "
                                                "the post-peak stop past the start transient")
    for section, keys in sections.items():
        lines += ["", f"[{section}]", *keys]
    lines.append("")
    text = "\n".join(lines)
    tomllib.loads(text)   # a preset that does not parse is never written
    return text


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("part", choices=("design", "backfill", "reseat", "fit", "best", "verify", "preset"))
    ap.add_argument("--csv", required=True, help="rows of the design (design, fit) or of the verification (verify)")
    ap.add_argument("--json", help="the fit's result (written by fit, read by verify)")
    ap.add_argument("--out", default=str(ROOT / "results" / "lab_calibration"), help="run folders")
    ap.add_argument("--n", type=int, default=14, help="Latin-hypercube points besides Tables 1 and 2 as printed")
    ap.add_argument("--design-seed", type=int, default=1, help="seed of the Latin hypercube")
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2], help="specimen seeds per point")
    ap.add_argument("--only", type=int, nargs="+", help="design points to run (default all)")
    ap.add_argument("--write", default=str(PRESET), help="the preset file (preset)")
    ap.add_argument("--verify-csv", help="best: the verification CSV that receives the chosen point's design rows")
    ap.add_argument("--design-csv", help="the design's CSV as the preset's header names it (preset; default: the "
                                         "path the fit read)")
    ap.add_argument("--square", nargs="*", default=[], choices=[v.name for v in lab_fit.FIT_VARIABLES],
                    help="variables with a square term in the surface (fit; default none: linear)")
    args = ap.parse_args(argv)
    if args.part == "design":
        pts = lab_fit.design(args.n, args.design_seed)
        for i, u in enumerate(pts):
            if args.only is None or i in args.only:
                run_point(i, u, args.seeds, Path(args.csv), Path(args.out))
        return 0
    if args.part == "backfill":
        print(f"{backfill(Path(args.csv), Path(args.out))} values filled in {args.csv}")
        return 0
    if args.part == "reseat":
        pairs = reseat(Path(args.csv), Path(args.out), args.n, args.design_seed)
        print(f"run again with {' '.join(STOP_KEYS)}: {pairs or 'no seating stop'}")
        return 0
    if args.part == "fit":
        result = fit(Path(args.csv), squared=tuple(args.square))
        Path(args.json).write_text(json.dumps(result, indent=1) + "\n")
        print(json.dumps({k: result[k] for k in ("surface_r2", "candidate_overrides", "predicted",
                                                  "predicted_weighted_residuals")}, indent=1))
        return 0
    if args.part == "best":
        rows = _rows(Path(args.csv))
        result = best_point(rows, Path(args.csv))
        Path(args.json).write_text(json.dumps(result, indent=1) + "\n")
        if args.verify_csv and not Path(args.verify_csv).exists():
            chosen = [dict(r, point=-1) for r in rows if int(r["point"]) == result["design_point"]]
            _write(Path(args.verify_csv), chosen)
        print(json.dumps({k: result[k] for k in ("design_point", "candidate_overrides", "predicted",
                                                  "predicted_weighted_residuals")}, indent=1))
        return 0
    result = json.loads(Path(args.json).read_text())
    u = np.array([result["candidate_u"][v.name] for v in lab_fit.FIT_VARIABLES])
    if args.part == "verify":
        run_point(-1, u, args.seeds, Path(args.csv), Path(args.out) / "verify")
        return 0
    Path(args.write).write_text(preset_text(result, _rows(Path(args.csv)), design_csv=args.design_csv))
    print(f"written {args.write}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
