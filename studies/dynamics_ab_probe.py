"""Probe: YADE's dynamics and the core's small-strain dynamics from one hand-over state, step by step.

    OMP_NUM_THREADS=1 /usr/bin/python3 -m studies.dynamics_ab_probe --params params/presets/fem.toml --seed 1 \
        [--handover 40] [--min-broken 0] [--steps 50,100,200,400,800,1600,3200] [--out probe.json]

Runs the hybrid engine's UCS (cascade limit ``--handover``, ``numerics.handover_cascade_bonds``) up to its first
dynamic stint that starts with at least ``--min-broken`` bonds broken, and takes that stint's start state (the state the
hybrid engine hands to YADE).  From it, with the platens fixed, both engines run the same number of steps at
YADE's time step, with the same damping: YADE's scene built from the state (``scene_from_state``) and the static
engine's inertial relaxation (:class:`grainfrac_yade.engines.static.inertial.InertialRelaxation`, its masses and contact
law).  At each step count it prints the bonds each has broken, the platen stress and the distance between their
displacement fields: where two models of the same network part, and by how much.
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import math
import shutil

import numpy as np

from grainfrac_yade import cli
from grainfrac_yade.engines.hybrid import scene as hybrid_scene
from grainfrac_yade.engines.static.cascade import LargeCascade
from grainfrac_yade.engines.static.inertial import FixedPlatens, InertialRelaxation
from grainfrac_yade.engines.yade import engine as dynamic_engine
from studies.pass_through_probe import initial_gap


class Captured(BaseException):
    """The hand-over state, out of the protocol's loop (a BaseException: no protocol handler takes it)."""

    def __init__(self, scene, start, state):
        super().__init__("captured")
        self.scene, self.start, self.state = scene, start, state


def capture_at(min_broken: int):
    """Make the hybrid scene's next stint with at least ``min_broken`` bonds broken raise :class:`Captured`."""
    run_stint = hybrid_scene.HybridScene._stint

    def stint(self, exc, held, retry=0):
        start = exc.state if isinstance(exc, LargeCascade) else self.path.last_converged
        if start is not None and int(start.broken.sum()) >= min_broken:
            self._take(start)
            raise Captured(self, start, self.export_state(self._platens()))
        return run_stint(self, exc, held, retry)

    hybrid_scene.HybridScene._stint = stint


class StopAfter(FixedPlatens):
    """Fixed platens that end the core's relaxation after ``checks`` equilibrium checks."""

    def __init__(self, checks: int):
        super().__init__(-math.inf)
        self.left = int(checks)

    def lost(self, stress: float) -> bool:
        self.left -= 1
        return self.left <= 0


class PassThrough:
    """``cn @ u`` as YADE's smooth joint reads it: D = initD - |initD + du_n| (opening du_n > 0), so a pair pressed
    beyond its initial gap g (du_n < -g) has passed the face and unloads: du_n -> -2 g - du_n."""

    def __init__(self, cn, gap):
        self.cn, self.gap = cn, gap

    def __matmul__(self, u):
        dn = self.cn @ u
        return np.where(dn < -self.gap, -2.0 * self.gap - dn, dn)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--params", default="params/presets/fem.toml")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--width", default="10e-3")
    ap.add_argument("--height", default="20e-3")
    ap.add_argument("--min-broken", type=int, default=0)
    ap.add_argument("--handover", type=int, default=40, help="numerics.handover_cascade_bonds of the hybrid UCS")
    ap.add_argument("--steps", default="50,100,200,400,800,1600,3200")
    ap.add_argument("--damping", type=float, default=None, help="both engines' damping (default the run's)")
    ap.add_argument("--no-rest", action="store_true",
                    help="the core runs every step asked for (its equilibrium check off), as YADE here")
    ap.add_argument("--pass-through", action="store_true",
                    help="the core's normal displacement as YADE's smooth joint measures it: |centre gap along the "
                         "face normal|, so that a pair pressed past its initial gap (the contact inset) unloads")
    ap.add_argument("--work", default="/tmp/dynamics_ab_probe")
    ap.add_argument("--out", default=None)
    a = ap.parse_args(argv)
    capture_at(a.min_broken)
    try:
        shutil.rmtree(a.work, ignore_errors=True)
        cli.main(["ucs", "--engine", "hybrid", "--params", a.params, "--seed", str(a.seed), "--width", a.width, "--height", a.height,
                  "--set", f"numerics.handover_cascade_bonds={a.handover}", "--out", a.work])
        raise SystemExit(f"no stint with {a.min_broken} bonds broken")
    except Captured as c:
        scene, start, state = c.scene, c.start, c.state
    params = scene.params
    dyn = dynamic_engine.scene_from_state(scene.specimen, params, state, scene.layout)
    ypl = dyn.attach_platens("free")
    ypl.set_axial_velocity(0.0)
    core_params = params
    if a.no_rest:
        core_params = dataclasses.replace(params, creep=dataclasses.replace(params.creep, equilibrium_tolerance=0.0))
    rel = InertialRelaxation(scene.eq, scene.masses(), core_params)
    core_dt = rel.dt
    rel.dt = dyn.dt
    if a.pass_through:
        rel.net = dataclasses.replace(rel.net, cn=PassThrough(rel.net.cn, initial_gap(scene)))
    if a.damping is not None:
        rel.damping = a.damping
        dyn.relaxation_damping(a.damping)
    period = params.creep.check_period
    u0 = start.u
    y0 = scene.displacements(dyn.export_state(ypl))
    rows = []
    print(f"start: strain {start.closure / scene.net.height:.5%}, stress {start.stress / 1e6:.2f} MPa, "
          f"{int(start.broken.sum())} broken; dt YADE {dyn.dt:.4g} s, core's own {core_dt:.4g} s; damping "
          f"{rel.damping}; |u_yade0 - u_static| / |u| = {np.linalg.norm(y0 - u0) / np.linalg.norm(u0):.3g}")
    done = 0
    for n in [int(x) for x in a.steps.split(",")]:
        dyn.run(n - done)
        done = n
        ys = dyn.export_state(ypl)
        uy = scene.displacements(ys)
        by = np.asarray(ys.bond_broken, bool)[scene.net.order]
        out = rel.relax(start, StopAfter(max(1, n // period)), scene.path.jt, scene.path.jc)
        cs, reason, steps = out[0], out[1], out[2]
        both = ~by & ~cs.broken
        fy = np.linalg.norm(np.asarray(ys.bond_normal_force), axis=1)[scene.net.order]
        dfn = np.abs(fy - np.abs(cs.fn))[both] / max(float(np.abs(cs.fn[both]).mean()), 1e-300)
        du = np.linalg.norm(uy - cs.u) / max(np.linalg.norm(uy - u0), 1e-300)
        row = {"steps": n, "core_steps": int(steps), "core_end": reason or "rest",
               "yade_broken": int(by.sum()), "core_broken": int(cs.broken.sum()),
               "only_yade": int((by & ~cs.broken).sum()), "only_core": int((cs.broken & ~by).sum()),
               "yade_stress_mpa": ypl.axial_stress() / 1e6, "core_stress_mpa": cs.stress / 1e6,
               "motion_distance": float(du), "normal_force_diff_max": float(dfn.max()),
               "normal_force_diff_median": float(np.median(dfn)),
               "yade_motion_m": float(np.abs(uy - u0).max()), "core_motion_m": float(np.abs(cs.u - u0).max())}
        rows.append(row)
        print(json.dumps(row))
    if a.out:
        with open(a.out, "w") as f:
            json.dump({"start_strain": start.closure / scene.net.height, "start_stress_pa": start.stress,
                       "start_broken": int(start.broken.sum()), "dt_yade": dyn.dt, "dt_core": core_dt,
                       "rows": rows}, f, indent=1)


if __name__ == "__main__":
    main()
