"""The hybrid engine's relaxation strategy of the static scene: YADE's dynamic relaxation where statics give out.

:class:`DynamicStints` is a relaxation strategy of :class:`grainfrac_yade.engines.static.scene.StaticScene`
(:class:`grainfrac_yade.engines.static.strategy.SceneRelaxation`: the protocols drive the scene as a static one,
displacement control along the sequentially linear path, the held platen stress of a creep hold).  Where the plain
static solve gives out it hands the scene's state to a dynamic engine (YADE's, given by the hybrid engine module
that composes the two, :mod:`.engine`; through the engine-neutral :class:`grainfrac_yade.engines.SceneState`) and
puts the outcome back through the scene's public hooks (:class:`grainfrac_yade.engines.static.strategy.
RelaxationHooks`).  It hands over at two points:

* **the static equilibrium gives out**: no set of frictional contact statuses settles (the core's
  :class:`~grainfrac_yade.errors.NumericalFailure`; frictional equilibria with non-associated slip need not be
  unique or exist), from the last converged state the path stood on;
* **a cascade grows**: more than ``numerics.handover_cascade_bonds`` bonds broken at one closure (0: never), from
  the state after the last of them (:class:`~grainfrac_yade.engines.static.cascade.LargeCascade`): the released energy may
  break more under inertia than the static cascade does.

A **dynamic stint** then relaxes YADE's scene from that state under the control the protocol had set: the platens
fixed where they are (a displacement-controlled test: UCS, the creep ramp) or YADE's stress servo at the held
stress (a creep hold), in the kernel's held-load loop (:func:`grainfrac_yade.kernel.held_relaxation.relax_held`, on
:class:`Stint`) with the creep protocol's own criteria: equilibrium (``creep.equilibrium_tolerance``, and the held
stress within ``creep.stress_tolerance``), collapse (:class:`~grainfrac_yade.kernel.held_relaxation.CollapseWatch`:
the servo saturated while the axial strain grows by ``creep.collapse_strain_increment``), checked every
``creep.check_period`` DEM steps within the hold's relaxation budget (``creep.max_relaxation_steps`` /
``_crossings``).  Bonds the creep law had handed over and the cascade had not yet broken are broken in YADE first.

At equilibrium (or, with the platens fixed, at the end of the budget) what the stint reached comes back: YADE's
relaxed state itself (nodes, broken set, each broken contact's shear reference from YADE's shear force), the static
equilibrium solved there; where that does not settle, the bonds YADE broke, in its order, each broken alone in the
static state the stint started from (:meth:`DynamicStints._take_back`); then the static cascade, and a held stress is
regained along the static path.  A stint after such unsettled hand-backs runs :data:`RETRY_CROSSINGS` wave crossings
more per one in a row.  Under a held stress a collapse (or no equilibrium within the budget) ends the hold as the
static failure rule does (the scene's ``hold_failure``), with the broken set YADE reached.  With the platens fixed,
a stint whose stress falls below the test's post-peak ratio x the stress it started from (the ratio the protocol
gave the scene, its ``load_loss_ratio``: the UCS test's ``ucs.stop_stress_ratio``) is the specimen failing: its
state (stress, broken set) is the scene's last, and the static path does not go on (:attr:`DynamicStints.
dynamic_end`).  Inertia is thus simulated only where the static path cannot go on.

Not bit-reproducible between processes once a stint ran (YADE sums fem node forces in an order keyed by memory
address, docs/studies/paper_fem.md); a run without stints is the static engine's, bit for bit.  Every stint is
logged (:attr:`DynamicStints.stints`) and summarised in summary.json (:meth:`DynamicStints.summary_keys`); its log
names the budget it ran under in YADE's DEM steps (one wave crossing, the servo's response, the relaxation budget):
the summary's ``wave_crossing_steps``, ``servo_response_steps_used`` and ``max_relaxation_steps_used`` are the creep
protocol's, counted in the static scene's load increments, not YADE's.  This module imports no engine but the
static one's strategy interface.
"""
from __future__ import annotations

import json
import math
import time

import numpy as np

from ...errors import NumericalFailure
from ...kernel.equilibrium import held_at_equilibrium, relaxed
from ...kernel.held_relaxation import HeldRelaxing, collapse_watch, relax_held
from ..static.cascade import LargeCascade
from ..static.strategy import SceneRelaxation
from .settings import not_used_settings
from ...wave import hold_budget, scene_density

#: Dynamic stints one static solve may call before the run ends as a numerical failure [1]: each stint leaves a
#: new broken set; where statics give out again at once, three stints in a row say that the hand-back does not
#: settle (a state the static model cannot hold in any status set).
MAX_STINTS_PER_SOLVE = 3
#: Elastic wave crossings a stint runs at least, per stint in a row whose state the static path could not go on from
#: [1]: a short stint leaves a state the static statuses do not settle in unchanged (at
#: paper size 50 DEM steps: the same unsettled closure three times), so each retry gives the dynamics one crossing
#: more to move away from it.
RETRY_CROSSINGS = 1.0
#: Smallest axial strain taken for the secant modulus that sets the servo's gain and the wave-crossing budget [1]
#: (the creep protocol's floor, so that a hand-over at zero strain still has a finite modulus).
SERVO_STRAIN_FLOOR = 1e-6


class Stint(HeldRelaxing):
    """A dynamic stint as the kernel's held-load loop relaxes it (:class:`~grainfrac_yade.kernel.held_relaxation.
    HeldRelaxing`): the dynamic scene ``dyn``'s DEM steps under YADE's servo (``servo``, a held stress) or its platens
    fixed (``stop_below`` [Pa]: the stress below which the load is lost, the UCS test's post-peak rule); at rest by
    the creep protocol's criterion over the intact bonds.  ``crossings`` receives the bonds broken in each elastic
    wave crossing of ``crossing_steps`` DEM steps, read at the first check past its end."""

    def __init__(self, dyn, platens, servo, creep_params, crossing_steps: float, stop_below, crossings: list):
        self.dyn, self.platens, self.servo, self.creep_params = dyn, platens, servo, creep_params
        self.crossing_steps, self.stop_below, self.crossings = crossing_steps, stop_below, crossings
        #: bonds broken when the current crossing began
        self.counted = int(dyn.broken.sum())

    def advance(self, steps: int) -> None:
        self.dyn.run(steps)

    def checked(self, done: int) -> None:
        if done >= (len(self.crossings) + 1) * self.crossing_steps:
            now = int(self.dyn.broken.sum())
            self.crossings.append(now - self.counted)
            self.counted = now

    def axial_strain(self) -> float:
        return self.platens.axial_strain()

    def lost(self) -> bool:
        return self.stop_below is not None and self.platens.axial_stress() < self.stop_below

    def balanced(self) -> bool:
        intact = np.flatnonzero(~self.dyn.broken)
        if self.servo is not None:
            return held_at_equilibrium(self.dyn, self.servo, intact, self.creep_params)
        return relaxed(self.dyn, intact, self.creep_params)


class DynamicStints(SceneRelaxation):
    """The hybrid engine's relaxation strategy of a static scene (:class:`grainfrac_yade.engines.static.strategy.
    SceneRelaxation`; module doc): where its plain static solve gives out, a dynamic stint on the engine that
    ``dynamic_engine()`` returns (YADE's engine module, looked up at the first stint), its outcome put back through
    the scene's hooks (:class:`grainfrac_yade.engines.static.strategy.RelaxationHooks`)."""

    engine_name = "hybrid"
    #: Where statics give out, the plain static path gives out and YADE's dynamic stint relaxes instead
    #: (``numerics.static_relaxation`` is not read).
    path_relaxation = "none"

    def __init__(self, dynamic_engine):
        #: () -> the dynamic engine module of the stints (called at each stint)
        self.dynamic_engine = dynamic_engine
        #: one dict per dynamic stint: why, where, outcome, DEM steps, bonds broken in it, CPU [s]
        self.stints: list[dict] = []
        #: why the specimen failed in a stint with the platens fixed ("" while it has not): its stress fell below
        #: the test's post-peak ratio x the stress the stint started from (the scene's ``load_loss_ratio``)
        self.dynamic_end = ""
        #: stints in a row whose state the static path could not go on from (each next stint runs longer)
        self.unsettled_hand_backs = 0

    def attach(self, scene) -> None:
        """A cascade above ``numerics.handover_cascade_bonds`` bonds gives out to a stint (0: never)."""
        scene.limit_cascade(scene.params.numerics.handover_cascade_bonds or None)

    # ------------------------------------------------------------------ the two solves that may hand over
    def move(self, scene, solve) -> None:
        if self.dynamic_end:
            raise NumericalFailure(f"hybrid: the static path cannot go on from a specimen that failed in a dynamic "
                                   f"stint ({self.dynamic_end})")
        if not self._retried(scene, solve, held=False):
            raise NumericalFailure(f"hybrid: {MAX_STINTS_PER_SOLVE} dynamic stints in a row did not give the static "
                                   f"path a state it can go on from (closure {scene.state.closure:.6g} m)")

    def hold(self, scene, solve) -> None:
        if not self._retried(scene, solve, held=True):
            raise NumericalFailure(f"hybrid: {MAX_STINTS_PER_SOLVE} dynamic stints in a row did not give the static "
                                   f"hold a state it can go on from (stress {scene.state.stress:.6g} Pa)")

    def _retried(self, scene, solve, held: bool) -> bool:
        """``solve()``, with a stint (:meth:`_attempt`) each time it gives out, at most :data:`MAX_STINTS_PER_SOLVE`
        stints: True once a solve went through or a stint ended the test (a held load lost: the solve once more,
        nothing solved, the servo counting its saturated steps; the platens fixed: :attr:`dynamic_end`); False
        where the statics gave out after the last stint."""
        for _ in range(MAX_STINTS_PER_SOLVE + 1):
            try:
                solve()
                self.unsettled_hand_backs = 0
                return True
            except (NumericalFailure, LargeCascade) as exc:
                self._attempt(scene, exc, held=held)
                if held and scene.hold_failure:
                    solve()
                    return True
                if not held and self.dynamic_end:
                    return True
        return False

    def _attempt(self, scene, exc, held: bool) -> None:
        """A stint from where ``exc`` left the static path; its take-back may itself meet a status set that does not
        settle: the bonds taken back so far stay broken, and the caller's next solve goes on from there."""
        before = len(self.stints)
        try:
            self._stint(scene, exc, held, self.unsettled_hand_backs)
        except (NumericalFailure, LargeCascade):
            if len(self.stints) == before:    # no stint ran: nothing to start it from
                raise
            self.stints[-1]["taken_back"] = False
            self.unsettled_hand_backs += 1
            return
        self.unsettled_hand_backs = 0

    # ------------------------------------------------------------------ the dynamic stint
    def _stint(self, scene, exc, held: bool, retry: int = 0) -> None:
        """Relax YADE's scene from the state where statics gave out (module doc); the static scene takes the
        outcome back.  NumericalFailure if there is no converged state to start from (a NaN, not a status cycle)."""
        start = exc.state if isinstance(exc, LargeCascade) else scene.last_converged()
        if start is None or not (math.isfinite(start.stress) and np.all(np.isfinite(start.fn))):
            raise exc
        c0 = time.process_time()
        scene.adopt(start)
        pending = scene.take_hand_overs()
        if not held:
            pending = np.zeros(0, np.int64)
        platens = scene.attached_platens()
        log = {"reason": str(exc).split(";")[0][:200], "held": held, "closure_m": float(start.closure),
               "stress_pa": float(start.stress), "broken_before": int(scene.broken.sum()) + len(pending)}
        dyn = self.dynamic_engine().scene_from_state(scene.specimen, scene.params, scene.export_state(platens),
                                                     scene.layout)
        ypl = dyn.attach_platens("free")
        if len(pending):
            modes = scene.failure_modes(start, pending)
            for m in np.unique(modes):
                dyn.break_bonds(pending[modes == m], int(m))
        crossings = []
        stop_ratio = None if held else scene.load_loss_ratio
        outcome, steps, servo, min_steps, budget = self._relax(scene, dyn, ypl, start, held, stop_ratio, retry,
                                                               crossings)
        log.update(outcome=outcome, dem_steps=int(steps), min_dem_steps=int(math.ceil(min_steps)),
                   wave_crossing_steps=float(budget.crossing_steps),
                   servo_response_steps=int(budget.servo_response_steps) if held else None,
                   max_relaxation_steps=int(budget.max_relaxation_steps),
                   broken_per_crossing=crossings,
                   broken_after=int(dyn.broken.sum()),
                   stress_after_pa=float(servo.stress if servo is not None else ypl.axial_stress()))
        log["cpu_s"] = time.process_time() - c0
        self.stints.append(log)
        dropped = stop_ratio is not None and log["stress_after_pa"] < stop_ratio * log["stress_pa"]
        if outcome == "equilibrium" and not dropped or (outcome == "budget" and not held and not dropped):
            self._take_back(scene, dyn, ypl, steps, log)
            log["cpu_s"] = time.process_time() - c0
            return
        if held:
            scene.fail_hold(f"dynamic stint: {outcome}: YADE from the static state could not hold "
                            f"{scene.hold_target:.6g} Pa ({log['reason']})")
        else:
            self.dynamic_end = (f"dynamic stint: with the platens fixed the stress fell from {log['stress_pa']:.6g} to "
                                f"{log['stress_after_pa']:.6g} Pa ({log['reason']})")
        # the platens as the stint left them: the run's last row shows the load the specimen kept
        scene.take_lost_load(dyn.broken, dyn.break_mode, ypl.axial_strain() * scene.height, log["stress_after_pa"],
                             steps)

    def _relax(self, scene, dyn, platens, start, held: bool, stop_ratio, retry: int = 0, crossings=None):
        """YADE's relaxation under the protocol's control, with the creep protocol's criteria: (outcome, DEM steps,
        servo or None, the DEM steps before the equilibrium check may end it: ``numerics.stint_min_crossings`` wave
        crossings, or :data:`RETRY_CROSSINGS` per ``retry`` where more, and the stint's
        :class:`~grainfrac_yade.wave.HoldBudget` in YADE's DEM steps); outcome "equilibrium", "collapse" (a held
        load), "lost load" (fixed platens: the stress below ``stop_ratio`` x the stint's start, the test's post-peak
        rule; None: never) or "budget" (none of these within the relaxation budget).  ``crossings`` (a list)
        receives the bonds YADE broke in each elastic wave crossing of the stint, read at the first check past each
        crossing's end (the last entry: the part-crossing the stint ended in)."""
        params = scene.params
        cp, height = params.creep, scene.height
        strain = max(start.closure / height, SERVO_STRAIN_FLOOR)
        young = max(start.stress, 0.0) / strain
        budget = hold_budget(cp, height, young, scene_density(params), dyn.dt)
        servo = watch = None
        if held:
            servo = platens.hold_stress(scene.hold_target, young, budget.servo_response_steps,
                                        cp.servo_max_strain_rate * height)
            watch = collapse_watch(cp, platens.axial_strain())
        else:
            platens.set_axial_velocity(0.0)
        if cp.relaxation_damping > 0:
            dyn.relaxation_damping(cp.relaxation_damping)
        min_steps = max(params.numerics.stint_min_crossings, retry * RETRY_CROSSINGS) * budget.crossing_steps
        stint = Stint(dyn, platens, servo, cp, budget.crossing_steps,
                      None if stop_ratio is None else stop_ratio * start.stress,
                      [] if crossings is None else crossings)
        end = relax_held(stint, budget.max_relaxation_steps, cp.check_period, watch=watch,
                         collapse_stress_ratio=cp.collapse_stress_ratio, min_steps=min_steps)
        stint.crossings.append(int(dyn.broken.sum()) - stint.counted)
        return end.outcome, end.steps, servo, min_steps, budget

    def _take_back(self, scene, dyn, platens, dem_steps: int, log: dict) -> None:
        """What the stint reached, into the static scene: first YADE's relaxed state itself
        (:meth:`~grainfrac_yade.engines.static.strategy.RelaxationHooks.take_relaxed_state`); where the static
        equilibrium does not settle from it, the bonds YADE broke, into the static state the stint started from
        (:meth:`~grainfrac_yade.engines.static.strategy.RelaxationHooks.take_breaks`).  ``log["taken_back"]`` names
        the way that worked.  The counters go on (steps: equilibria and the stint's DEM steps; time: the load
        parameter, DEM time not added)."""
        scene.add_steps(dem_steps)
        try:
            scene.take_relaxed_state(dyn.export_state(platens))
            log["taken_back"] = "state"
            return
        except (NumericalFailure, LargeCascade):
            pass
        scene.take_breaks(dyn.broken, dyn.break_step, dyn.break_mode)
        log["taken_back"] = "breaks"

    # ------------------------------------------------------------------ records
    def summary_keys(self, scene) -> dict:
        """The engine's name, no unused settings (the stints use the dynamic ones), and the stints' totals and log."""
        return {"engine": self.engine_name, "settings_not_used": not_used_settings(scene.params),
                "dynamic_stints": len(self.stints),
                "dynamic_stint_dem_steps": int(sum(s["dem_steps"] for s in self.stints)),
                "dynamic_stint_cpu_s": float(sum(s["cpu_s"] for s in self.stints)),
                "dynamic_stint_log": list(self.stints),
                "engine_failure_reason": scene.hold_failure or self.dynamic_end}

    def saved_arrays(self) -> dict:
        return {"hybrid_stints": np.str_(json.dumps(self.stints)), "hybrid_dynamic_end": np.str_(self.dynamic_end)}

    def restore_arrays(self, arrays: dict) -> None:
        self.stints = json.loads(str(arrays["hybrid_stints"])) if "hybrid_stints" in arrays else []
        self.dynamic_end = str(arrays["hybrid_dynamic_end"]) if "hybrid_dynamic_end" in arrays else ""


