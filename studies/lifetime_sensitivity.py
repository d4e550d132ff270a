"""What moves the fem lifetime: paired changes of ln t_f and of the contact-stress tail, per modelling choice.

    /usr/bin/python3 -m studies.lifetime_sensitivity results/lifetime_sensitivity_static \
        --out docs/studies/paper_static/lifetime_sensitivity

Reads the run folders of ``params/lifetime_sensitivity_static_small.table`` (descriptions ``<variant>_s<seed>``) and,
per variant against ``base`` on the same seed: d ln t_f (both failed), d ln t_(k) of the k-th shortest time to
failure of a contact at creep start under its frozen stresses (paper Eq. 7 integrated: (J - s) / (beta1
exp(beta2 s)) per channel, s = sigma_n in tension, tau in shear, from bond_stresses_start.csv), and the stress shift
that change of the tail is worth, -d ln t_(k) / beta2 [MPa].  Writes ``<out>.csv`` (one row per run) and
``<out>.md`` (one row per variant: mean and range over the seeds).
"""
from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import numpy as np
import pandas as pd

#: The k of the tail's k-th shortest contact time to failure [1].
TAIL_RANK = 10


def contact_times(stresses: pd.DataFrame, beta1: float, beta2: float) -> np.ndarray:
    """(bonds,) each intact contact's time to failure at creep start under frozen stresses [s] (Eq. 7): the shorter
    of its tension channel (sigma_n > 0) and its shear channel; inf where neither corrodes to failure."""
    out = np.full(len(stresses), math.inf)
    for stress, util in ((stresses.normal_stress_pa.to_numpy(), stresses.tensile_utilisation.to_numpy()),
                         (stresses.shear_stress_pa.to_numpy(), stresses.shear_utilisation.to_numpy())):
        ok = (stress > 0) & (util > 0) & (util < 1)
        margin = np.where(ok, stress * (1.0 / np.where(ok, util, 1.0) - 1.0), math.inf)
        out = np.minimum(out, margin / (beta1 * np.exp(beta2 * np.where(ok, stress, 0.0))))
    return out


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


def variant_table(runs: pd.DataFrame) -> pd.DataFrame:
    base = runs[runs.variant == "base"].set_index("seed")
    tail = f"tail_time_{TAIL_RANK}_s"
    rows = []
    for variant, g in runs.groupby("variant", sort=False):
        g = g.set_index("seed")
        both = [s for s in g.index if s in base.index and g.failed[s] and base.failed[s]]
        d_life = np.array([math.log(g.lifetime_s[s] / base.lifetime_s[s]) for s in both])
        d_tail = np.array([math.log(g[tail][s] / base[tail][s]) for s in g.index if s in base.index])
        shift = -d_tail / g.beta2_per_pa.iloc[0] / 1e6
        rows.append({"variant": variant, "seeds_failed": f"{int(g.failed.sum())} of {len(g)}",
                     "dln_tf_mean": d_life.mean() if len(d_life) else math.nan,
                     "dln_tf_min": d_life.min() if len(d_life) else math.nan,
                     "dln_tf_max": d_life.max() if len(d_life) else math.nan, "paired_seeds": len(d_life),
                     "dln_tail_mean": d_tail.mean(), "tail_shift_mpa_mean": shift.mean(),
                     "broken_ramp_mean": g.broken_ramp.mean(), "cpu_s_mean": g.cpu_s.mean()})
    return pd.DataFrame(rows)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("study")
    ap.add_argument("--out", required=True)
    a = ap.parse_args(argv)
    folders = sorted(p.parent for p in Path(a.study).glob("*/summary.json"))
    runs = pd.DataFrame([run_row(f) for f in folders]).sort_values(["variant", "seed"], kind="stable")
    runs.to_csv(a.out + ".csv", index=False)
    table = variant_table(runs)
    lines = ["| variant | failed | d ln t_f mean (min / max) over paired seeds | d ln t_(10) at creep start | "
             "tail shift [MPa] | bonds broken in the ramp | CPU [s] |", "|---|---|---|---|---|---|---|"]
    for r in table.itertuples():
        life = (f"{r.dln_tf_mean:+.2f} ({r.dln_tf_min:+.2f} / {r.dln_tf_max:+.2f}), {r.paired_seeds}"
                if r.paired_seeds else "-")
        lines.append(f"| {r.variant} | {r.seeds_failed} | {life} | {r.dln_tail_mean:+.2f} | "
                     f"{r.tail_shift_mpa_mean:+.1f} | {r.broken_ramp_mean:.0f} | {r.cpu_s_mean:.0f} |")
    Path(a.out + ".md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
