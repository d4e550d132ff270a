"""``calibrate-lifetimes STUDY --lab CSV``: fit beta1, beta2 (and optionally the activation threshold) of a
strength law so that the model's lifetimes match lab lifetimes in ln t, by least squares
(:mod:`grainfrac_yade.analysis.lifetime_calibration`).

The model is the parameter set of ``--params``/``--set`` (the law: ``hillig_charles`` or ``normalised``,
event clock) on specimens of ``--seeds``, loaded at the lab's driving-stress ratios of ``--ucs``.
beta1 is an exact time scale (no runs); every beta2 (and threshold) tried needs one creep run per lab
ratio and seed: the command plans them as yade-batch rows into ``STUDY/calibrate/<trial>/`` and runs
them (``--jobs`` at a time).  A finished run anywhere in STUDY with the same parameters, seed and load is
reused, so a study made earlier (e.g. params/lifetime_small.table) and an interrupted calibration cost
nothing twice.  Writes the calibrated parameter file (``--out``) with the fit before and after and the
data used, and ``STUDY/calibrate/fit.csv``.
"""
from __future__ import annotations

import hashlib
import json
import math
from pathlib import Path

from ..analysis.lifetime_calibration import ModelPoint, fit
from ..errors import GrainfracError
from ..law import scales_with_beta1, time_scaling_laws
from ..params import flat_values, load_parameters, require_plane, write_parameter_file
from ..runs.batchrun import run_batch, write_table
from ..runs.runio import code_version, comparable_parameters, write_csv
from ._args import float_list_type, seed_list_type
from ._loads import stress_flag

#: Keys of the fitted parameters, by law.
BETA2_KEY = {"hillig_charles": "stress_corrosion.beta2", "normalised": "stress_corrosion.beta2_normalised"}
THRESHOLD_KEY = "stress_corrosion.threshold_ratio"
#: Relative tolerance on the creep stress when reusing a finished run.
STRESS_RTOL = 1e-9
DEFAULT_SEEDS = (1, 2, 3)


def register(sub, common):
    p = sub.add_parser("calibrate-lifetimes", help="fit beta1, beta2 (and a threshold) to lab lifetimes (runs "
                                                   "the creep rows it needs through yade-batch)")
    common(p)
    p.add_argument("study", help="study folder: its finished creep runs are reused; new runs go to STUDY/calibrate/")
    p.add_argument("--lab", required=True, help="CSV driving_stress_ratio,lifetime_s[,source]")
    p.add_argument("--seeds", type=seed_list_type, default=None,
                   help="specimen seeds of each ratio (default: those of the study's creep runs, else 1,2,3)")
    p.add_argument("--ucs", type=stress_flag, default=None, metavar="MPA",
                   help="UCS [MPa, like every stress flag; files and batch columns in Pa] the lab ratios refer to (default: the study's runs' ucs_pa if they agree, else "
                        "calibration.reference_ucs)")
    p.add_argument("--threshold-ratios", type=float_list_type, default=None, metavar="R1,R2,...",
                   help="also fit stress_corrosion.threshold_ratio among these values, e.g. 0,0.3,0.4")
    p.add_argument("--jobs", type=int, default=1, help="creep runs at a time")
    p.set_defaults(func=cmd_calibrate_lifetimes, with_params=True)


def _digest(tree: dict) -> str:
    """Identity of a parameter tree (params.json layout) for reuse: every key that changes results."""
    from ..analysis.study import VARIANT_IGNORE
    flat = {k: v for k, v in comparable_parameters(tree).items() if k not in VARIANT_IGNORE}
    return hashlib.sha256(json.dumps(flat, sort_keys=True).encode()).hexdigest()


def finished_runs(study: Path) -> list:
    """(params digest, seed, stress [Pa], summary, folder) of every finished creep run under ``study``."""
    out = []
    for summary_file in sorted(study.rglob("summary.json")):
        folder = summary_file.parent
        try:
            run = json.loads((folder / "run.json").read_text())
            if run.get("command") != "creep":
                continue
            summary = json.loads(summary_file.read_text())
            tree = json.loads((folder / "params.json").read_text())
        except (OSError, ValueError):
            continue
        out.append((_digest(tree), int(run.get("seed")), float(summary["stress_pa"]), summary, folder))
    return out


def model_point(ratio, summaries) -> "ModelPoint | None":
    """The model at one ratio from its seeds' summaries: geometric mean of the lifetimes; a lower bound if a
    seed did not fail; None if no seed gives a value (failed on loading, numerical failure, broken apart before the
    test)."""
    logs, censored, notes = [], False, []
    for s in summaries:
        if s.get("numerical_failure"):
            notes.append("numerical failure")
        elif s.get("failed_before_test"):
            notes.append("broke apart before the test")
        elif s.get("failed_on_loading"):
            notes.append("failed on loading")
        elif s.get("failed"):
            logs.append(math.log(s["lifetime_s"]) if s["lifetime_s"] > 0 else -math.inf)
        else:
            logs.append(math.log(s["creep_time_end_s"]))
            censored = True
            notes.append("not failed by the creep-time limit (lower bound)")
    logs = [v for v in logs if math.isfinite(v)]
    if not logs:
        return None
    return ModelPoint(float(ratio), sum(logs) / len(logs), censored, len(logs), "; ".join(sorted(set(notes))))


class BatchModel:
    """The model as a function of (beta2, threshold): creep runs at every lab ratio and seed, made through
    yade-batch (missing rows only) or reused from the study."""

    def __init__(self, args, params, ratios, seeds, ucs, study: Path, progress=print):
        self.args, self.params, self.ratios, self.seeds, self.ucs = args, params, ratios, seeds, ucs
        self.study, self.progress = study, progress
        self.base = flat_values(args.params, args.resolved_overrides)
        self.beta2_key = BETA2_KEY[params.stress_corrosion.law]
        self.runs = 0

    def trial_params(self, beta2, threshold):
        extra = [(self.beta2_key, beta2), (THRESHOLD_KEY, threshold)]
        return load_parameters(extra_files=self.args.params, overrides=list(self.args.resolved_overrides) + extra)

    def __call__(self, beta2, threshold):
        params = self.trial_params(beta2, threshold)
        digest = _digest(params.to_dict())
        known = [r for r in finished_runs(self.study) if r[0] == digest]
        name = f"{self.beta2_key.split('.')[-1]}_{beta2!r}_threshold_{threshold!r}"
        found, rows = {}, []
        for ratio in self.ratios:
            stress = ratio * self.ucs
            for seed in self.seeds:
                match = [r for r in known if r[1] == seed and math.isclose(r[2], stress, rel_tol=STRESS_RTOL)]
                if match:
                    found[(ratio, seed)] = match[0][3]
                    continue
                out = self.study / "calibrate" / name / f"ratio{ratio:g}_seed{seed}"
                rows.append(dict(self.base, **{self.beta2_key: beta2, THRESHOLD_KEY: threshold}, ratio=ratio,
                                 ucs=self.ucs, seed=seed, out=str(out),
                                 description=f"{name}_ratio{ratio:g}_seed{seed}"))
        if rows:
            repo = Path(__file__).resolve().parents[2]
            folder = self.study / "calibrate" / name
            table = write_table(folder / "creep.table", rows, f"calibrate-lifetimes: {name}")
            self.progress(f"running {len(rows)} creep rows ({name}), {self.args.jobs} at a time")
            run_batch(table, repo / "yade_scripts" / "creep.py", self.args.jobs, folder / "logs", repo=repo)
            self.runs += len(rows)
            done = {(r[1], r[4]): r for r in finished_runs(folder) if r[0] == digest}
            for row in rows:
                run = done.get((row["seed"], Path(row["out"])))
                if run is None:
                    raise GrainfracError(f"{row['out']}: the creep row did not finish with these parameters (see "
                                         f"{folder / 'logs'}); fix: check its log, then run the command again "
                                         "(finished rows are reused)")
                found[(row["ratio"], row["seed"])] = run[3]
        points = {}
        for ratio in self.ratios:
            p = model_point(ratio, [found[(ratio, s)] for s in self.seeds])
            if p is not None:
                points[float(ratio)] = p
        return points


def _study_defaults(study: Path, seeds, ucs):
    """Seeds and UCS of the study's finished creep runs where not given."""
    runs = finished_runs(study) if study.is_dir() else []
    if seeds is None:
        seeds = sorted({r[1] for r in runs}) or list(DEFAULT_SEEDS)
    if ucs is None:
        values = {round(float(r[3]["ucs_pa"]), 3) for r in runs if r[3].get("ucs_pa")}
        ucs = values.pop() if len(values) == 1 else None
    return seeds, ucs


def _fit_lines(result, trial, beta1) -> list:
    rows = result.table(trial, beta1)
    return [f"  ratio {r['ratio']:.4g}: lab {r['lab_s']:.4g} s, model {r['model_s']:.4g} s"
            f"{' (lower bound)' if r['censored'] else ''}, residual {r['residual_ln']:+.3f} ln s"
            for r in rows]


def cmd_calibrate_lifetimes(args, params) -> int:
    from ..analysis.labdata import read_lab_csv
    require_plane(params, "calibrate-lifetimes")
    sc = params.stress_corrosion
    if not scales_with_beta1(sc.law) or sc.clock != "event":
        raise GrainfracError(f"law {sc.law!r} with the {sc.clock} clock: beta1 is an exact time scale only for the "
                             f"laws whose times scale with it ({', '.join(time_scaling_laws())}) with the event "
                             "clock; fix: --set "
                             "stress_corrosion.law=hillig_charles --set stress_corrosion.clock=event")
    if sc.rate_form != "beta":
        raise GrainfracError("stress_corrosion.rate_form = physical: beta1 and beta2 follow from paper Eq. 6; fix: "
                             "calibrate with rate_form = beta")
    study = Path(args.study)
    lab = read_lab_csv(args.lab)
    seeds, ucs = _study_defaults(study, args.seeds, args.ucs)
    ucs = ucs or params.calibration.reference_ucs
    ratios = sorted({float(r) for r in lab["driving_stress_ratio"]})
    if max(ratios) >= 1:
        raise GrainfracError(f"{args.lab}: a driving-stress ratio of {max(ratios):g} is at or above the UCS; fix: "
                             "ratios in (0, 1)")
    model = BatchModel(args, params, ratios, seeds, ucs, study)
    beta2 = getattr(sc, BETA2_KEY[sc.law].split(".")[1])
    thresholds = args.threshold_ratios if args.threshold_ratios else [sc.threshold_ratio]
    print(f"calibrate-lifetimes: {len(lab)} lab points at {len(ratios)} ratios of {ucs / 1e6:.1f} MPa, seeds {seeds}, "
          f"law {sc.law}, start beta1 {sc.beta1:g} Pa/s, beta2 {beta2:g}, threshold(s) {thresholds}")
    result = fit(model, lab, sc.beta1, beta2, thresholds, sc.threshold_ratio, progress=print)
    out = Path(args.out or study / "calibrate" / "stress_corrosion_calibrated.toml")
    values = {"stress_corrosion.beta1": result.beta1, BETA2_KEY[sc.law]: result.beta2}
    if args.threshold_ratios:
        values[THRESHOLD_KEY] = result.threshold
    header = [
        f"Stress-corrosion constants fitted to lab lifetimes in ln t (least squares), law {sc.law}.",
        f"Use: --params {out}   (merged over the shipped files and the model's own --params)",
        f"Written by: python3 -m grainfrac_yade calibrate-lifetimes {study} --lab {args.lab}   ({code_version()})",
        f"Model: {params.specimen.width * 1e3:g} x {params.specimen.height * 1e3:g} mm, seeds {seeds}, ratios of "
        f"{ucs / 1e6:.2f} MPa, event clock; {model.runs} creep runs made, {len(result.trials)} parameter sets tried.",
        "Lab data used (driving_stress_ratio, lifetime_s, source):",
        *(f"  {r:.4g}, {t:.6g}, {s}" for r, t, s in zip(lab["driving_stress_ratio"], lab["lifetime_s"], lab["source"])),
        f"Before: beta1 {result.beta1_run:g} Pa/s, beta2 {result.before.beta2:g}, threshold "
        f"{result.before.threshold:g}; "
        f"sum of squared ln residuals {_cost(result, result.before, result.beta1_run):.4g}",
        *_fit_lines(result, result.before, result.beta1_run),
        f"After: beta1 {result.beta1:.6g} Pa/s, beta2 {result.beta2:.6g}, threshold {result.threshold:g}; sum of "
        f"squared ln residuals {result.after.cost:.4g}",
        *_fit_lines(result, result.after, result.beta1),
        "beta1 is an exact time scale of the strength laws (every creep time ~ 1/beta1); beta2 and the threshold",
        "were run (STUDY/calibrate/). Lower bounds: runs that reached stress_corrosion.creep_time_limit unbroken.",
    ]
    notes = {"stress_corrosion.beta1": f"fitted (start {result.beta1_run:g})",
             BETA2_KEY[sc.law]: f"fitted (start {result.before.beta2:g})",
             THRESHOLD_KEY: f"fitted among {thresholds}"}
    out.parent.mkdir(parents=True, exist_ok=True)
    write_parameter_file(out, values, header, notes)
    table = [dict(r, fit=name) for name, trial, b1 in (("before", result.before, result.beta1_run),
                                                       ("after", result.after, result.beta1))
             for r in result.table(trial, b1)]
    (study / "calibrate").mkdir(parents=True, exist_ok=True)
    write_csv(study / "calibrate" / "fit.csv", table)
    print(f"beta1 {result.beta1:.6g} Pa/s, beta2 {result.beta2:.6g}, threshold {result.threshold:g}: sum of squared "
          f"ln residuals {_cost(result, result.before, result.beta1_run):.4g} -> {result.after.cost:.4g} "
          f"({model.runs} creep runs) -> {out}")
    return 0


def _cost(result, trial, beta1):
    return sum(r["residual_ln"] ** 2 for r in result.table(trial, beta1) if math.isfinite(r["residual_ln"]))
