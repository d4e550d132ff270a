"""Constant-load creep test to failure with stress corrosion (paper section 4.1).

0. Confined tests (``confinement.stress`` sigma_3 > 0): side-wall forces, then the isotropic
   stage to sigma_1 = sigma_3 at equilibrium (:mod:`.confinement`).
1. Ramp: strain-controlled platens (``creep.ramp_strain_rate``) until the axial
   stress reaches the target; bonds broken during the ramp are counted apart.
2. Hold: a servo keeps the axial stress at the target (:class:`StressServo`).
3. Creep: the degradation law (:mod:`grainfrac_yade.law`) acts as creep time
   passes, with the ``event`` clock (at equilibrium, one pure
   :func:`~grainfrac_yade.law.creep_step` to the next failure, ours) or the
   ``paper`` clock (Eq. 8: creep step doubling while the unbalanced force is below
   the threshold, applied every ``engine_period`` DEM steps).  This module reads
   forces and writes strengths (:mod:`.corrosion_engine`); the law is not here.

Failure: the platens cannot hold the load.  Collapse (:class:`CollapseWatch`): the
servo closes the platens at its speed limit on every DEM step while the axial strain
grows by more than ``creep.collapse_strain_increment`` (the specimen carries less
than the load however far it is squeezed; 0 = criterion off).  Backstop: no
equilibrium at the held stress within ``creep.max_relaxation_steps`` DEM steps (the
strain runs away).  Safety cap: the axial strain exceeds ``creep.failure_strain``.
Lifetime is the creep time at failure.  Creep time is separate from DEM time.

Numerical failure: NaN or infinite forces, stresses or strains (the DEM blew
up), or ``MAX_STALLED_INTERVALS`` creep intervals of length 0 in a row that
break no bond, end the run with ``numerical_failure`` set and the reason in
``failure_reason``: neither a lifetime nor a survival.

Checkpoints (given a run folder): every ``numerics.checkpoint_interval`` s of wall time
in the ramp, always at its end, then every interval again at a safe point of the clock loops
(:meth:`CreepRun.safe_point`); :func:`resume_creep` goes on from the last one and
computes what the uninterrupted run would have (:mod:`.checkpoint`).
"""
from __future__ import annotations

import math
import time

import numpy as np

from ..clocks import EventClock, PaperClock
from ..errors import NumericalFailure
from ..law import creep_step, shear_strength
from ..params import unbalanced_threshold
from .checkpoint import Checkpointer, inexact_note, read, restore
from .confinement import Confinement, consolidate, young_estimate
from .corrosion_engine import StressCorrosion, add_stiffness_restorer
from .platens import Platens, StressServo, free_bodies, held_at_equilibrium
from .scene import broken_counts, build_scene, check_value, resultant_forces
from .vtk_output import Series, write_creep_snapshot

#: Length of a UDEC 2D model's out-of-plane unit [m]: the paper's absolute F_u threshold (100 N)
#: is per metre of thickness; it is scaled by the layer thickness here.
UDEC_UNIT_THICKNESS = 1.0
#: Events between progress lines.
PROGRESS_EVERY = 20
#: History rows between writes of the partial history (an interrupted run keeps what it measured).
HISTORY_FLUSH_ROWS = 50
#: Event clock: creep intervals of length 0 in a row that break no bond (a bond handed over at its
#: failure point that the contact law does not break) before the run ends as a numerical failure.
MAX_STALLED_INTERVALS = 10


#: The ramp fails on loading when the platen stress falls below RAMP_DROP_FRACTION of its peak, once
#: that peak exceeds RAMP_DROP_MIN_PEAK of the target: at the start of the ramp the stress of a
#: specimen set in motion from rest oscillates (6 x 12 mm deformable cells: 6.8 then 4.3 MPa at
#: axial strains of 3e-5 and 5e-5), which must not read as a failure.  A specimen weaker than that
#: fraction of the load fails on loading at ``creep.failure_strain`` instead.
RAMP_DROP_FRACTION = 0.7
RAMP_DROP_MIN_PEAK = 0.5


class CollapseWatch:
    """Collapse of a specimen under the held load, recognised from the stress servo.

    A servo saturated closing (its command clipped at +max speed) drives the platens together as
    fast as it may because the specimen carries less than the target stress; when that lasts while
    the axial strain grows by more than ``strain_increment``, the specimen is shortening without
    regaining the load: it has collapsed.  A transient stress drop after a break that the specimen
    recovers from ends the saturation before that, and any interruption starts the count again.

    Fed once per check with ``saturated`` (the servo was clipped closing on every DEM step since the
    previous check) and the axial strain at the check; :meth:`update` says whether collapse is
    reached.  A saturated stretch is measured from the strain at the check before its first
    saturated one (where the saturated DEM steps began).  ``strain_increment`` 0: criterion off.
    """

    def __init__(self, strain_increment: float, strain: float):
        self.strain_increment = float(strain_increment)
        #: axial strain at the previous check [1]
        self.previous = float(strain)
        #: axial strain where the current saturated stretch began [1]; None: not saturated
        self.start = None
        #: saturated checks in a row
        self.checks = 0

    @property
    def growth(self) -> float:
        """Axial strain gained in the current saturated stretch [1] (0 when not saturated)."""
        return 0.0 if self.start is None else self.previous - self.start

    def update(self, saturated: bool, strain: float) -> bool:
        """One check; True when the saturated stretch has gained more than ``strain_increment``."""
        if saturated:
            if self.start is None:
                self.start = self.previous
            self.checks += 1
        else:
            self.start, self.checks = None, 0
        self.previous = float(strain)
        return self.strain_increment > 0 and self.start is not None and self.growth > self.strain_increment

    def reason(self, steps_per_check: int) -> str:
        """The failure reason once collapse is reached."""
        return (f"collapse: servo at its closing speed limit for {self.checks * steps_per_check} DEM steps while "
                f"the axial strain grew by {self.growth:.6g} > collapse_strain_increment {self.strain_increment:g}")

    def state_dict(self) -> dict:
        return {"previous": self.previous, "start": self.start, "checks": self.checks}

    @classmethod
    def from_state(cls, strain_increment: float, state: dict) -> "CollapseWatch":
        watch = cls(strain_increment, state["previous"])
        watch.start, watch.checks = state["start"], int(state["checks"])
        return watch


def collapsing(servo, steps: int, stress_ratio: float) -> bool:
    """One check of :class:`CollapseWatch`: the servo closed the platens at its speed limit on each of the
    last ``steps`` DEM steps and the held stress is below ``stress_ratio`` x its target (the specimen
    carries a fraction of the load; a cascade it arrests keeps more)."""
    return servo.closing_clipped_steps >= steps and servo.stress < stress_ratio * servo.target


class CreepRun:
    """State and bookkeeping of one creep test."""

    def __init__(self, specimen, params, target_stress, progress=None, vtk_folder=None, vtk_times=(),
                 vtk_every=0, history_sink=None, checkpoint_folder=None, run_values=None):
        self.params, self.target = params, target_stress
        #: VTK snapshots: folder and the creep times [s] still to write (the first equilibrium state
        #: at or after each time; the final state is always written when a folder is given)
        self.vtk_folder, self.vtk_times = vtk_folder, sorted(float(t) for t in vtk_times)
        #: also a snapshot at every ``vtk_every``-th history row (one row per creep step or event; 0: none)
        self.vtk_every = int(vtk_every)
        self.vtk_written = []
        self._vtk_rows = -1   # number of history rows when the last snapshot was written
        #: called with the rows so far every HISTORY_FLUSH_ROWS rows (partial history.csv)
        self.history_sink = history_sink
        self.progress = progress or (lambda msg: None)
        self.t0, self.c0 = time.time(), time.process_time()   # wall and CPU time of the run's start
        self.scene = build_scene(specimen, params)
        self.platens = Platens(self.scene, params.ucs.platen_lateral)
        self.scene.extras.append(self.platens)
        #: side-wall forces of a confined test (``confinement.stress`` > 0), else None
        self.confinement = None
        #: the isotropic stage of a confined test (:func:`.confinement.consolidate`): steps, equilibrium
        self.consolidation = {}
        if params.confinement.stress > 0:
            self.confinement = Confinement(self.scene, params.confinement.stress)
            self.scene.extras.append(self.confinement)
        self._free_ids = free_bodies(self.scene, self.platens)
        self.rows, self.ramp_broken = [], 0
        self.failed, self.failure_reason = False, ""
        self.failed_on_loading = False   # failed during the ramp: lifetime 0, no creep phase
        self.numerical_failure = False   # NaN/inf or a stalled clock: no result (failure_reason says why)
        self.corr = None
        self.n_events = 0
        self.initial_bond_stresses = None
        self.break_time = np.full(self.scene.n_bonds, np.nan)
        #: creep time at which each bond's face was first seen fully separated (macrocrack) [s]
        self.macro_time = np.full(self.scene.n_bonds, np.nan)
        #: writes checkpoints into ``checkpoint_folder`` (a run folder), None: no checkpoints
        self.checkpointer = None
        if checkpoint_folder is not None:
            self.checkpointer = Checkpointer(checkpoint_folder, params.numerics.checkpoint_interval, run_values or {},
                                             self.progress)
        #: (phase, loop counters) to go on from after :func:`resume_creep`; None: a run from the start
        self.resumed = None
        #: the checkpoints this run was resumed from (DEM step, creep time, phase, when written)
        self.resumes = []

    # ------------------------------------------------------------------ measures
    def unbalanced(self, mean_bond_force):
        """Largest resultant force on a free body [N], and mean / mean_bond_force (bodies: cells, or the
        spheres of deformable cells)."""
        largest, mean = resultant_forces(self.scene, self._free_ids)
        rel = mean / mean_bond_force if mean_bond_force > 0 else math.inf
        return largest, rel

    def at_equilibrium(self, servo):
        bonds = self.corr.intact() if self.corr is not None else np.flatnonzero(~self.scene.broken)
        return held_at_equilibrium(self.scene, servo, self._free_ids, bonds, self.params.creep)

    def record(self, creep_time, stress=None):
        """Append a history row; NumericalFailure (and no row) if a value is NaN or infinite."""
        row = {
            "creep_time_s": creep_time, "axial_strain": self.platens.axial_strain(),
            "lateral_strain": self.platens.lateral_strain(),
            "axial_stress_pa": self.platens.axial_stress() if stress is None else stress,
            **broken_counts(self.scene), "macrocracks": self.count_macrocracks(creep_time),
            "dem_steps": int(self.scene.O.iter), "wall_s": time.time() - self.t0}
        for key, value in row.items():
            check_value(f"history {key}", value, row["dem_steps"])
        self.rows.append(row)

    def count_macrocracks(self, creep_time):
        """Broken bonds on faces whose every bond is broken and open (cells fully separated).

        Marks ``macro_time`` of bonds seen separated for the first time with ``creep_time``.
        """
        sc = self.scene
        idx = np.flatnonzero(sc.broken)
        if not len(idx):
            return 0
        open_ = sc.bond_separated(idx)
        face = sc.layout.bond_face
        n_faces = sc.specimen.tessellation.n_faces
        bonds_per_face = np.bincount(face, minlength=n_faces)
        open_per_face = np.bincount(face[idx[open_]], minlength=n_faces)
        separated = (bonds_per_face == open_per_face) & (bonds_per_face > 0)
        macro = idx[separated[face[idx]]]
        self.macro_time[macro[np.isnan(self.macro_time[macro])]] = creep_time
        return len(macro)

    def mark_breaks(self, creep_time):
        new = np.flatnonzero(self.scene.broken & np.isnan(self.break_time))
        self.break_time[new] = creep_time

    # ------------------------------------------------------------------ phases
    def ramp(self, resume=None):
        """Strain-controlled loading to the target stress; ``resume``: the counters of a checkpoint taken
        in it (phase ``loading``: the scene, platens and their speed came back with it)."""
        cp = self.params.creep
        if resume is None:
            self.platens.set_axial_velocity(cp.ramp_strain_rate * self.platens.height)
        steps = max(1, int(round(1e-5 / (cp.ramp_strain_rate * self.scene.O.dt))))
        peak = 0.0 if resume is None else float(resume["peak"])
        while True:
            if self.scene.O.iter > 0:   # not before the first step: the bonds' reference state is set by it
                self.safe_point("loading", {"peak": peak})
            self.scene.run(steps)
            s = self.platens.axial_stress()
            check_value("axial stress during the ramp", s, self.scene.O.iter)
            peak = max(peak, s)
            if s >= self.target:
                break
            dropped = peak > RAMP_DROP_MIN_PEAK * self.target and s < RAMP_DROP_FRACTION * peak
            if self.platens.axial_strain() > cp.failure_strain or dropped:
                self.failed, self.failure_reason = True, "failed during the ramp: load above the specimen's strength"
                self.failed_on_loading = True
                break
        self.mark_breaks(0.0)
        self.ramp_broken = int(self.scene.broken.sum())
        self.break_time[self.scene.broken] = -1.0  # ramp cracks: before creep time 0

    def hold_servo(self):
        """Hold the load with the stress servo from here on; the creep phase's damping
        (``creep.relaxation_damping``, if set) replaces the ramp's."""
        cp = self.params.creep
        if cp.relaxation_damping > 0:
            self.scene.newton.damping = cp.relaxation_damping
        young = max(self.target / max(self.platens.axial_strain(), 1e-6), 1e9)
        self.servo = StressServo(self.platens, self.target, young, cp.servo_response_steps,
                                 cp.servo_max_strain_rate * self.platens.height)
        self.scene.drivers.append(self.servo)

    def relax(self, creep_time):
        """Run DEM steps until equilibrium at the held load; False (and failed) at collapse
        (:class:`CollapseWatch`, checked every ``creep.check_period`` steps) or if equilibrium does not
        come within ``creep.max_relaxation_steps``."""
        cp = self.params.creep
        done = 0
        self.last_relaxation_steps = 0
        watch = (CollapseWatch(cp.collapse_strain_increment, self.platens.axial_strain())
                 if cp.collapse_strain_increment > 0 else None)
        while done < cp.max_relaxation_steps:
            self.scene.run(cp.check_period)
            done += cp.check_period
            self.last_relaxation_steps = done
            self.mark_breaks(creep_time)
            if self.check_failure():
                return False
            if watch is not None and watch.update(collapsing(self.servo, cp.check_period, cp.collapse_stress_ratio),
                                                  self.platens.axial_strain()):
                self.failed, self.failure_reason = True, watch.reason(cp.check_period)
                return False
            if self.at_equilibrium(self.servo):
                return True
        self.failed, self.failure_reason = True, "no equilibrium at the held load (strain runs away)"
        return False

    def bond_stress_table(self) -> dict:
        """Normal (tension positive) and shear stress of every intact bond, with its utilisation."""
        corr = self.corr
        idx = corr.intact()
        st = corr.stresses(idx)
        sigma, tau = st.normal, st.shear
        jt, jc = corr.strengths(idx)
        limit = shear_strength(jc, sigma, corr.tan_phi[idx])
        return {"bond": idx, "normal_stress_pa": sigma, "shear_stress_pa": tau,
                "tensile_utilisation": sigma / jt, "shear_utilisation": np.where(limit > 0, tau / limit, np.inf),
                "inter": self.scene.bond_is_inter[idx]}

    def run_event_clock(self, resume=None):
        """Event clock loop; ``resume``: its counters at a checkpoint (the clock is restored with it)."""
        if resume is None:
            self.clock = EventClock(self.params.stress_corrosion.max_strength_loss_fraction,
                                    self.params.stress_corrosion.creep_time_limit)
        self.n_events = event_clock_loop(self, self.corr, self.clock, resume)

    def run_paper_clock(self, resume=None):
        """Paper clock loop; ``resume``: its counters at a checkpoint (the clock is restored with it)."""
        sc = self.params.stress_corrosion
        if resume is None:
            self.clock = PaperClock(sc.dt_min, sc.dt_max, unbalanced_threshold(sc))
        paper_clock_loop(self, self.corr, self.clock, self.params.stress_corrosion, self.params.creep, resume)
        self.n_events = int(np.sum(self.break_time > 0))

    def safe_point(self, phase, loop):
        """A point between DEM steps where the driver's state is complete (``phase``: "loading" (in the
        ramp), "ramp" (its end), "event", "paper"; ``loop``: the ramp's or the clock loop's counters):
        write a checkpoint if one is due, always at the end of the ramp, else every
        ``numerics.checkpoint_interval`` s of wall time."""
        ck = self.checkpointer
        if ck is not None and (phase == "ramp" or ck.due()):
            ck.write(self, phase, loop)

    def check_failure(self):
        """Set ``failed`` if the axial strain passed the cap; return it."""
        cp = self.params.creep
        if self.platens.axial_strain() > cp.failure_strain:
            self.failed, self.failure_reason = True, f"axial strain above {cp.failure_strain}"
        return self.failed

    def record_now(self, creep_time):
        self.record(creep_time, self.servo.stress)
        while self.vtk_folder is not None and self.vtk_times and self.vtk_times[0] <= creep_time:
            self.vtk_times.pop(0)
            self.write_vtk(creep_time)
        if self.vtk_folder is not None and self.vtk_every and len(self.rows) % self.vtk_every == 0:
            self.write_vtk(creep_time)
        if self.history_sink is not None and len(self.rows) % HISTORY_FLUSH_ROWS == 0:
            self.history_sink(self.rows)

    def write_vtk(self, creep_time):
        """Snapshot of the current state, unless the last one was taken at this same history row
        (only reads the scene)."""
        if self.corr is not None and self._vtk_rows != len(self.rows):
            write_creep_snapshot(Series(self.vtk_folder, times=self.vtk_written), self, creep_time)
            self.vtk_written.append(creep_time)
            self._vtk_rows = len(self.rows)

    def run(self):
        """Ramp, hold and creep; a NumericalFailure ends the run with ``numerical_failure`` set."""
        try:
            return self._run()
        except NumericalFailure as exc:
            self.numerical_failure = True
            self.failure_reason = f"numerical failure: {exc}"
            self.progress(self.failure_reason)
            return self

    def _run(self):
        phase, loop = self.resumed or (None, None)
        if phase in (None, "loading"):
            if phase is None and self.confinement is not None:
                self.consolidation = consolidate(self.scene, self.platens, self.confinement.stress, self.params.creep,
                                                 young_estimate(self.params))
            self.ramp(loop if phase == "loading" else None)
            self.record(0.0)
            self.macro_time[np.isfinite(self.macro_time)] = -1.0  # separated during the ramp
            if self.failed:
                return self
            self.safe_point("ramp", {})
        if phase in (None, "loading", "ramp"):
            self.hold_servo()
            if not self.params.stress_corrosion.enabled:
                # control run: the load is held, nothing corrodes; equilibrium must come and stay
                if self.relax(0.0):
                    self.scene.run(self.params.creep.max_relaxation_steps)
                    self.check_failure()
                self.record(0.0, self.servo.stress)
                return self
            self.corr = StressCorrosion(self.scene, self.params.stress_corrosion)
            self.scene.extras.append(self.corr)
            add_stiffness_restorer(self.scene, self.corr)
            if self.relax(0.0):
                self.initial_bond_stresses = self.bond_stress_table()
            loop = None
        # else: servo, stress corrosion and clock came back with the checkpoint; the loop goes on from it
        if self.params.stress_corrosion.clock == "event":
            self.run_event_clock(loop)
        else:
            self.run_paper_clock(loop)
        if self.vtk_folder is not None:
            self.write_vtk(self.rows[-1]["creep_time_s"])
        return self


def _no_checkpoint(phase, loop):
    """Stand-in for :meth:`CreepRun.safe_point` for holders without checkpoints."""


def event_clock_loop(holder, corr, clock, resume=None) -> int:
    """Event clock (ours): at equilibrium, one :func:`~grainfrac_yade.law.creep_step` under the frozen
    stresses (to the next bond failure, or the law's loss cap); write, hand over, relax; repeat.

    ``holder`` relaxes the scene (``relax(creep_time) -> bool``), records rows (``record_now``) and
    reports progress. Returns the number of events (intervals that ended in a failure).  Each pass
    starts at a safe point (``holder.safe_point("event", counters)``, a checkpoint if due);
    ``resume``: the counters of such a point, to go on from it (scene and clock restored).
    """
    safe_point = getattr(holder, "safe_point", _no_checkpoint)
    if resume is None:
        n_events = stalled = 0
        ok = holder.relax(0.0)
        holder.record_now(0.0)   # also when that first relaxation fails: its cracks belong to the run
        if not ok:
            return n_events
    else:
        n_events, stalled = int(resume["n_events"]), int(resume["stalled"])
    while True:
        safe_point("event", {"n_events": n_events, "stalled": stalled})
        broken_before = int(corr.scene.broken.sum())
        idx = corr.intact()
        stresses = corr.stresses(idx)
        step = creep_step(corr.law, clock, corr.state, stresses)
        if step.stalled:
            break
        corr.state = step.state
        corr.write(idx)
        if len(step.failing):
            corr.hand_over_failures(step.failing, stresses.normal[step.positions], stresses.shear[step.positions],
                                    step.modes)
            n_events += 1
        clock.advance(step.dt, step.failing)
        corr.creep_time = clock.creep_time
        ok = holder.relax(clock.creep_time)
        holder.record_now(clock.creep_time)
        if n_events % PROGRESS_EVERY == 0 and len(step.failing):
            holder.progress(f"t {clock.creep_time:.4g} s  events {n_events}  broken "
                            f"{int(corr.scene.broken.sum())}  relaxation {holder.last_relaxation_steps} steps")
        if not ok or clock.finished:
            break
        stalled = stalled + 1 if step.dt == 0 and int(corr.scene.broken.sum()) == broken_before else 0
        if stalled >= MAX_STALLED_INTERVALS:
            raise NumericalFailure(f"{stalled} creep intervals of length 0 in a row broke no bond (creep time "
                                   f"{clock.creep_time:.6g} s): a bond at its failure point that the contact law "
                                   "does not break")
    return n_events



def paper_clock_loop(holder, corr, clock, sc, cp, resume=None):
    """Paper clock (Eq. 8): every ``engine_period`` DEM steps advance creep time by the doubled or
    reset step and degrade all intact bonds for it (the law's degrade, paper Eq. 7 by default).

    Each pass starts at a safe point (``holder.safe_point("paper", counters)``, a checkpoint if
    due); ``resume``: the counters of such a point, to go on from it (scene and clock restored).

    One notion of balance: F_u below the clock's threshold (:meth:`PaperClock.balanced`) both
    doubles the step and resets the count of DEM steps without balance; more than
    ``creep.max_relaxation_steps`` such steps in a row is the failure "no equilibrium".  Before
    that, collapse (:class:`CollapseWatch`, checked every ``engine_period`` DEM steps) ends the run
    when ``creep.collapse_strain_increment`` > 0 and the holder has a stress servo.

    F_u is the largest resultant force on a free cell; ``absolute`` compares it, per metre of
    thickness as in UDEC 2D, with the threshold (100 N); ``relative`` uses the mean resultant over
    the mean bond force.  With ``engine_period`` k > 1 the k steps share the F_u of the last one.
    While F_u is at or above the threshold the law is applied every ``unbalanced_engine_period`` DEM
    steps instead (the step then sits at dt_min: the steps add k x dt_min of creep time).
    """
    scale = corr.scene.specimen.thickness / UDEC_UNIT_THICKNESS
    safe_point = getattr(holder, "safe_point", _no_checkpoint)
    increment = getattr(cp, "collapse_strain_increment", 0.0)
    unbalanced_period = getattr(sc, "unbalanced_engine_period", sc.engine_period)
    servo = getattr(holder, "servo", None)
    if resume is None:
        holder.record_now(0.0)
        applications, not_balanced_steps = 0, 0
        period = sc.engine_period
    else:
        applications, not_balanced_steps = int(resume["applications"]), int(resume["not_balanced_steps"])
        period = int(resume.get("period", sc.engine_period))
    watch = None
    if increment > 0 and servo is not None:
        saved = (resume or {}).get("collapse")
        watch = (CollapseWatch.from_state(increment, saved) if saved
                 else CollapseWatch(increment, holder.platens.axial_strain()))
    while True:
        counters = {"applications": applications, "not_balanced_steps": not_balanced_steps}
        if period != sc.engine_period:
            counters["period"] = period
        if watch is not None:
            counters["collapse"] = watch.state_dict()
        safe_point("paper", counters)
        corr.scene.run(period)
        # a bond breaks in these DEM steps because the last creep step took it past its failure point
        # (or its neighbours' did): it broke at the creep time that step reached, not at the next one;
        # the steps run after the last creep step too, so no bond ends the run past its failure point
        holder.mark_breaks(clock.creep_time)
        idx = corr.intact()
        if not len(idx):   # nothing left to corrode, and no bond force for the relative F_u
            if not holder.check_failure():
                holder.failed, holder.failure_reason = True, "every bond broken"
            break
        if clock.creep_time >= sc.creep_time_limit:
            break
        stresses = corr.stresses(idx)
        mean_force = float(np.mean(np.hypot(stresses.normal, stresses.shear) * corr.area0[idx]))
        f_max, rel = holder.unbalanced(mean_force)
        f_u = f_max / scale if sc.unbalanced_force_reference == "absolute" else rel
        dt_b = clock.advance_many([f_u] * period)
        corr.degrade(dt_b, stresses)
        applications += 1
        balanced = clock.balanced(f_u)
        not_balanced_steps = 0 if balanced else not_balanced_steps + period
        if applications % cp.record_period == 0:
            holder.record_now(clock.creep_time)
        if applications % (PROGRESS_EVERY * 100) == 0:
            holder.progress(f"t {clock.creep_time:.4g} s  step {clock.dt:.3g} s  F_u {f_u:.3g}  broken "
                            f"{int(corr.scene.broken.sum())}  applications {applications}")
        collapsed = watch is not None and watch.update(collapsing(servo, period, cp.collapse_stress_ratio),
                                                       holder.platens.axial_strain())
        if not holder.check_failure() and collapsed:
            holder.failed, holder.failure_reason = True, watch.reason(period)
        elif not holder.failed and not_balanced_steps > cp.max_relaxation_steps:
            holder.failed, holder.failure_reason = True, (
                f"no equilibrium at the held load (strain runs away): F_u at or above the paper clock's "
                f"threshold {clock.unbalanced_force_threshold:g} for {not_balanced_steps} DEM steps")
        if holder.failed:
            break
        period = sc.engine_period if balanced else unbalanced_period
    holder.record_now(clock.creep_time)


def run_creep(specimen, params, target_stress, progress=None, **outputs) -> CreepRun:
    """Ramp, hold and creep ``specimen`` at ``target_stress`` [Pa]; returns the finished run.

    ``outputs``: ``vtk_folder``, ``vtk_times`` and ``vtk_every`` (VTK snapshots), ``history_sink`` (partial history),
    ``checkpoint_folder`` (the run folder: checkpoints in its ``checkpoint/``) and ``run_values``
    (seed, load: stored with the checkpoints).
    """
    return CreepRun(specimen, params, target_stress, progress, **outputs).run()


def resume_creep(specimen, params, target_stress, run_folder, progress=None, **outputs) -> CreepRun:
    """Go on with the creep run whose checkpoint is in ``run_folder`` (same specimen, parameters and
    load as the run that wrote it) and return the finished run; it writes further checkpoints there.

    The scene is built as for a new run, then replaced by the checkpoint's (``O.load``) and the
    driver's state is restored (:func:`.checkpoint.restore`).  GrainfracError if the folder holds
    no usable checkpoint.
    """
    where, state, arrays = read(run_folder)
    outputs.setdefault("run_values", state.get("run_values"))
    run = CreepRun(specimen, params, target_stress, progress, checkpoint_folder=run_folder, **outputs)
    run.resumed = restore(run, where, state, arrays)
    run.progress(f"resumed from the checkpoint at DEM step {state['dem_steps']}, creep time "
                 f"{state['creep_time_s']:.6g} s ({state['phase']} phase)")
    if inexact_note(params):
        run.progress(f"note: not bit-identical: {inexact_note(params)}")
    return run.run()
