"""What moves the fem lifetime: paired changes of ln t_f and of the contact-stress tail, per modelling choice.

    /usr/bin/python3 -m studies.lifetime_sensitivity results/lifetime_sensitivity_static \
        --out docs/studies/paper_static/lifetime_sensitivity

Reads the run folders of ``params/lifetime_sensitivity_static_small.table`` (descriptions ``<variant>_s<seed>``) and,
per variant against ``base`` on the same seed: d ln t_f (both failed), d ln t_(k) of the k-th shortest time to
failure of a contact at creep start under its frozen stresses (paper Eq. 7 integrated: (J - s) / (beta1
exp(beta2 s)) per channel, from bond_stresses_start.csv), and the stress shift
that change of the tail is worth, -d ln t_(k) / beta2 [MPa].  Writes ``<out>.csv`` (one row per run) and
``<out>_variants.csv`` and ``<out>.md`` (one row per variant: the change per seed, a run that did not fail as a lower
bound, and the mean over the seeds where both failed).
"""
from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import numpy as np
import pandas as pd

from grainfrac_yade.api import time_to_failure

#: The k of the tail's k-th shortest contact time to failure [1].
TAIL_RANK = 10


def contact_times(stresses: pd.DataFrame, beta1: float, beta2: float) -> np.ndarray:
    """(bonds,) each intact contact's time to failure at creep start under frozen stresses [s]: paper Eq. 7's closed
    form (:func:`grainfrac_yade.law.hillig_charles.time_to_failure`), its strengths read back from the stresses and
    utilisations of bond_stresses_start.csv (J^T = sigma / u_T; the shear strength J^C + s_n tan(phi) = tau / u_S,
    carried by the cohesion channel)."""
    sigma, tau = stresses.normal_stress_pa.to_numpy(), stresses.shear_stress_pa.to_numpy()
    u_t, u_s = stresses.tensile_utilisation.to_numpy(), stresses.shear_utilisation.to_numpy()
    return time_to_failure(sigma / u_t, tau / u_s, sigma, tau, 0.0, beta1, beta2)[0]


def run_row(folder: Path) -> dict:
    summary = json.loads((folder / "summary.json").read_text())
    params = json.loads((folder / "params.json").read_text())
    sc = params.get("stress_corrosion", params.get("params", {}).get("stress_corrosion", {}))
    beta1, beta2 = float(sc["beta1"]), float(sc["beta2"])
    times = np.sort(contact_times(pd.read_csv(folder / "bond_stresses_start.csv"), beta1, beta2))
    description = json.loads((folder / "run.json").read_text()).get("description", folder.name.split("__")[0])
    variant, seed = description.rsplit("_s", 1)
    return {"variant": variant, "seed": int(seed), "failed": bool(summary["failed"]),
            "lifetime_s": float(summary["lifetime_s"] if summary["failed"] else math.nan), "n_events": int(summary["n_events"]),
            "broken_ramp": int(summary["broken_ramp"]), "n_bonds": int(summary["n_bonds"]),
            f"tail_time_{TAIL_RANK}_s": float(times[TAIL_RANK - 1]), "beta2_per_pa": beta2,
            "cpu_s": float(summary["cpu_s"]), "folder": folder.name}


def paired_changes(g: pd.DataFrame, base: pd.DataFrame, limit: float) -> list:
    """Per seed (base failed): (seed, d ln t_f, censored) of a variant's runs ``g`` against ``base`` (both indexed by
    seed); a variant run that did not fail by ``limit`` [s] gives the lower bound ln(limit / t_base)."""
    out = []
    for seed in g.index:
        if seed in base.index and base.failed[seed]:
            if g.failed[seed]:
                out.append((seed, math.log(g.lifetime_s[seed] / base.lifetime_s[seed]), False))
            else:
                out.append((seed, math.log(limit / base.lifetime_s[seed]), True))
    return out


def variant_table(runs: pd.DataFrame, limit: float) -> pd.DataFrame:
    """One row per variant: its paired changes of ln t_f against ``base`` (censored ones as lower bounds), the mean
    over the seeds where both failed, and the median change of the tail (all seeds: a tail time near zero, a specimen
    that hardly holds the load, would swamp a mean)."""
    base = runs[runs.variant == "base"].set_index("seed")
    tail = f"tail_time_{TAIL_RANK}_s"
    rows = []
    for variant, g in runs.groupby("variant", sort=False):
        g = g.set_index("seed")
        pairs = paired_changes(g, base, limit)
        exact = [d for _, d, censored in pairs if not censored]
        d_tail = np.array([math.log(g[tail][s] / base[tail][s]) for s in g.index if s in base.index])
        rows.append({"variant": variant, "seeds_failed": f"{int(g.failed.sum())} of {len(g)}",
                     "dln_tf_mean": float(np.mean(exact)) if exact else math.nan, "paired_seeds": len(exact),
                     "dln_tf_per_seed": ", ".join(f"s{s} {'>' if c else ''}{d:+.2f}" for s, d, c in pairs),
                     "dln_tail_median": float(np.median(d_tail)),
                     "tail_shift_mpa_median": -float(np.median(d_tail)) / g.beta2_per_pa.iloc[0] / 1e6,
                     "broken_ramp_mean": g.broken_ramp.mean(), "cpu_s_mean": g.cpu_s.mean()})
    return pd.DataFrame(rows)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("study")
    ap.add_argument("--out", required=True)
    ap.add_argument("--creep-time-limit", type=float, default=1e9,
                    help="the runs' stress_corrosion.creep_time_limit [s]: a run not failed by it is a lower bound")
    a = ap.parse_args(argv)
    folders = sorted(p.parent for p in Path(a.study).glob("*/summary.json"))
    runs = pd.DataFrame([run_row(f) for f in folders]).sort_values(["variant", "seed"], kind="stable")
    runs.to_csv(a.out + ".csv", index=False)
    table = variant_table(runs, a.creep_time_limit)
    table.to_csv(a.out + "_variants.csv", index=False)
    lines = ["| variant | failed | d ln t_f per seed (> : not failed by the time limit, a lower bound) | mean where both "
             "failed | d ln t_(10) at creep start, median | tail shift [MPa] | bonds broken in the ramp | CPU [s] |",
             "|---|---|---|---|---|---|---|---|"]
    for r in table.itertuples():
        mean = f"{r.dln_tf_mean:+.2f} ({r.paired_seeds})" if r.paired_seeds else "-"
        lines.append(f"| {r.variant} | {r.seeds_failed} | {r.dln_tf_per_seed} | {mean} | {r.dln_tail_median:+.2f} | "
                     f"{r.tail_shift_mpa_median:+.1f} | {r.broken_ramp_mean:.0f} | {r.cpu_s_mean:.0f} |")
    Path(a.out + ".md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
