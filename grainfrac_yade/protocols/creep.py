"""Constant-load creep test to failure with stress corrosion (paper section 4.1).

0. Confined tests (``confinement.stress`` sigma_3 > 0): side-wall forces, then the isotropic
   stage to sigma_1 = sigma_3 at equilibrium (the engine's ``consolidate``).  A specimen that breaks apart in
   it (:func:`grainfrac_yade.kernel.confinement.broken_apart_reason`) ends the run there with ``failed_before_test`` set
   and the reason in ``failure_reason``: no ramp, no creep, neither a lifetime nor a survival.
1. Ramp: strain-controlled platens (``creep.ramp_strain_rate``) until the axial
   stress reaches the target; bonds broken during the ramp are counted apart.
2. Hold: a servo keeps the axial stress at the target (the platens' ``hold_stress``,
   :class:`grainfrac_yade.engines.PlatenDrive`); the creep phase's damping (``creep.relaxation_damping``)
   is the scene's ``relaxation_damping`` (an engine without damping ignores it).
3. Creep: the degradation law (:mod:`grainfrac_yade.law`) acts as creep time
   passes, with the ``event`` clock (at equilibrium, one pure
   :func:`~grainfrac_yade.law.creep_step` to the next failure, ours) or the
   ``paper`` clock (Eq. 8: creep step doubling while the unbalanced force is below
   the threshold, applied every ``engine_period`` DEM steps; a dynamic engine only,
   :func:`grainfrac_yade.engines.registry.require_dynamic`).  The engine's ``stress_corrosion`` hook
   reads the bond forces and writes the strengths (the law's state:
   :class:`grainfrac_yade.kernel.corrosion.BondCorrosion`); the law is not here.

Failure: the platens cannot hold the load (the kernel's held-load loop,
:func:`grainfrac_yade.kernel.held_relaxation.relax_held`).  Collapse
(:class:`~grainfrac_yade.kernel.held_relaxation.CollapseWatch`): the servo closes the platens at its
speed limit on every DEM step while the axial strain grows by more than
``creep.collapse_strain_increment`` (the specimen carries less than the load however far it is
squeezed; 0 = criterion off).  Backstop: no
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
computes what the uninterrupted run would have (:mod:`.checkpoints`; :mod:`.creep_checkpoint`: the run's own
state beside the engine's scene).

Written against the scene interface (:class:`grainfrac_yade.engines.Scene`): any engine runs it.
"""
from __future__ import annotations

import dataclasses
import time

import numpy as np

from ..clocks import EventClock, PaperClock
from ..engines.registry import engine_for, require_dynamic
from ..errors import NumericalFailure
from ..kernel.equilibrium import check_value, held_at_equilibrium
from ..kernel.held_relaxation import BUDGET, COLLAPSE, EQUILIBRIUM, HeldRelaxing, collapse_watch, relax_held
from ..law import shear_strength
from ..params import unbalanced_threshold
from ..vtkio import due_times, merged_frame_note
from ..wave import hold_budget, scene_density
from .checkpoints import Checkpointer, inexact_note, read
from .creep_checkpoint import capture, restore
from ..kernel.confinement import broken_apart_reason
from ..kernel.cracks import bond_is_inter, broken_counts
from .creep_loops import event_clock_loop, paper_clock_loop
from .snapshots import Series, write_creep_snapshot

#: History rows between writes of the partial history (an interrupted run keeps what it measured).
HISTORY_FLUSH_ROWS = 50

#: The ramp fails on loading when the platen stress falls below RAMP_DROP_FRACTION of its peak, once
#: that peak exceeds RAMP_DROP_MIN_PEAK of the target: at the start of the ramp the stress of a
#: specimen set in motion from rest oscillates (6 x 12 mm, cells of the retired spring lattice: 6.8
#: then 4.3 MPa at axial strains of 3e-5 and 5e-5), which must not read as a failure.  A specimen weaker than that
#: fraction of the load fails on loading at ``creep.failure_strain`` instead.
RAMP_DROP_FRACTION = 0.7
RAMP_DROP_MIN_PEAK = 0.5
#: Axial strain between the ramp's checks of stress, target and failure [1]: the DEM steps of one
#: check at ``creep.ramp_strain_rate``.  Small against a ramp to the target (about 3e-3 at 0.7 x the
#: UCS), so the load overshoots the target by at most 1e-5 x E (0.7 MPa at 70 GPa); checks cost a
#: platen read each, nothing more.
RAMP_CHECK_STRAIN = 1e-5
#: The servo's guess of the specimen's axial modulus is the held stress over the axial strain (the
#: secant modulus at the end of the ramp); this floor on the strain [1] keeps it finite at a zero
#: strain (a target of 0), far below any strain a ramp ends at (about 1e-3).
SERVO_STRAIN_FLOOR = 1e-6
#: Floor on that modulus guess [Pa]: 1 GPa, 70 x below the granite's E, so that a tiny or zero
#: target (secant 0) still gives the servo a finite gain; the gain only sets how fast the servo
#: removes its error (``creep.servo_response_steps``), not where it holds.
SERVO_MODULUS_FLOOR = 1e9


class CreepHold(HeldRelaxing):
    """A creep run's held load as the kernel's loop relaxes it (:class:`~grainfrac_yade.kernel.held_relaxation.
    HeldRelaxing`): its scene's DEM steps; after each chunk the breaks marked at ``creep_time``, the strain cap
    (:meth:`CreepRun.check_failure`), the servo's collapse and its equilibrium (:meth:`CreepRun.at_equilibrium`)."""

    def __init__(self, run: "CreepRun", creep_time: float):
        self.run, self.creep_time, self.servo = run, creep_time, run.servo

    def advance(self, steps: int) -> None:
        self.run.scene.run(steps)

    def checked(self, done: int) -> None:
        self.run.last_relaxation_steps = done
        self.run.mark_breaks(self.creep_time)

    def failure(self) -> str:
        return self.run.failure_reason if self.run.check_failure() else ""

    def axial_strain(self) -> float:
        return self.run.platens.axial_strain()

    def balanced(self) -> bool:
        return self.run.at_equilibrium(self.servo)


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
        #: requested times that fell into one frame: [{"requested_s": [...], "frame_s": t}] (summary.json)
        self.vtk_merged = []
        self._vtk_rows = -1   # number of history rows when the last snapshot was written
        #: called with the rows so far every HISTORY_FLUSH_ROWS rows (partial history.csv)
        self.history_sink = history_sink
        self.progress = progress or (lambda msg: None)
        self.t0, self.c0 = time.time(), time.process_time()   # wall and CPU time of the run's start
        #: the engine of ``params`` (``numerics.engine``): builds the scene, the isotropic stage, the bond writer
        self.engine = engine_for(params)
        self.scene = self.engine.build_scene(specimen, params)
        self.platens = self.scene.attach_platens(params.ucs.platen_lateral)
        # the ramp loads as the UCS test does (its platens, its post-peak rule for a relaxation with them held)
        self.scene.lose_load_below(params.ucs.stop_stress_ratio)
        #: side-wall forces of a confined test (``confinement.stress`` > 0), else None
        self.confinement = None
        #: the isotropic stage of a confined test (the engine's ``consolidate``): steps, equilibrium
        self.consolidation = {}
        if params.confinement.stress > 0:
            self.confinement = self.scene.confine(params.confinement.stress)
        self.rows, self.ramp_broken = [], 0
        self.failed, self.failure_reason = False, ""
        self.failed_on_loading = False   # failed during the ramp: lifetime 0, no creep phase
        self.numerical_failure = False   # NaN/inf or a stalled clock: no result (failure_reason says why)
        #: broke apart in the isotropic stage of a confined test: no creep test (failure_reason says why)
        self.failed_before_test = False
        self.corr = None
        #: the stress servo that holds the load (:meth:`hold_servo`) and the creep clock (:meth:`creep`);
        #: None before the ramp ends
        self.servo = None
        #: DEM steps of the hold (wave crossing, servo response, relaxation budget): set with the servo
        self.hold_budget = None
        self.clock = None
        #: DEM steps of the last relaxation to equilibrium
        self.last_relaxation_steps = 0
        self.n_events = 0
        self.initial_bond_stresses = None
        self.break_time = np.full(self.scene.n_bonds, np.nan)
        #: creep time at which each bond's face was first seen fully separated (macrocrack) [s]
        self.macro_time = np.full(self.scene.n_bonds, np.nan)
        #: writes checkpoints into ``checkpoint_folder`` (a run folder), None: no checkpoints
        self.checkpointer = None
        if checkpoint_folder is not None:
            self.checkpointer = Checkpointer(checkpoint_folder, params.numerics.checkpoint_interval, run_values or {},
                                             self.progress, capture=capture)
        #: (phase, loop counters) to go on from after :func:`resume_creep`; None: a run from the start
        self.resumed = None
        #: the checkpoints this run was resumed from (DEM step, creep time, phase, when written)
        self.resumes = []

    # ------------------------------------------------------------------ measures
    def unbalanced(self, mean_bond_force):
        """Largest resultant force on a free body [N], and mean / mean_bond_force (bodies: cells, or the
        spheres of fem cells)."""
        return self.scene.unbalanced(mean_bond_force)

    def at_equilibrium(self, servo):
        bonds = self.corr.intact() if self.corr is not None else np.flatnonzero(~self.scene.broken)
        return held_at_equilibrium(self.scene, servo, bonds, self.params.creep)

    def record(self, creep_time, stress=None):
        """Append a history row; NumericalFailure (and no row) if a value is NaN or infinite."""
        row = {
            "creep_time_s": creep_time, "axial_strain": self.platens.axial_strain(),
            "lateral_strain": self.platens.lateral_strain(),
            "axial_stress_pa": self.platens.axial_stress() if stress is None else stress,
            **broken_counts(self.scene), "macrocracks": self.count_macrocracks(creep_time),
            "step": int(self.scene.steps), "wall_s": time.time() - self.t0}
        for key, value in row.items():
            check_value(f"history {key}", value, row["step"])
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
        steps = max(1, int(round(RAMP_CHECK_STRAIN / (cp.ramp_strain_rate * self.scene.dt))))
        peak = 0.0 if resume is None else float(resume["peak"])
        while True:
            if self.scene.steps > 0:   # not before the first step: the bonds' reference state is set by it
                self.safe_point("loading", {"peak": peak})
            self.scene.run(steps)
            s = self.platens.axial_stress()
            check_value("axial stress during the ramp", s, self.scene.steps)
            peak = max(peak, s)
            if s >= self.target:
                break
            dropped = peak > RAMP_DROP_MIN_PEAK * self.target and s < RAMP_DROP_FRACTION * peak
            if self.platens.axial_strain() > cp.failure_strain or dropped:
                self.failed, self.failure_reason = True, "failed during the ramp: load above the specimen's strength"
                self.failed_on_loading = True
                break
        self.count_loading_cracks()

    def count_loading_cracks(self):
        """The bonds broken so far (isotropic stage and ramp) are the ramp's: counted apart, before creep time 0."""
        self.mark_breaks(0.0)
        self.ramp_broken = int(self.scene.broken.sum())
        self.break_time[self.scene.broken] = -1.0  # ramp cracks: before creep time 0

    def hold_servo(self):
        """Hold the load with the stress servo from here on; the creep phase's damping
        (``creep.relaxation_damping``, if set) replaces the ramp's."""
        cp = self.params.creep
        if cp.relaxation_damping > 0:
            self.scene.relaxation_damping(cp.relaxation_damping)
        young = max(self.target / max(self.platens.axial_strain(), SERVO_STRAIN_FLOOR), SERVO_MODULUS_FLOOR)
        self.hold_budget = hold_budget(cp, self.platens.height, young, scene_density(self.params), self.scene.dt)
        self.servo = self.platens.hold_stress(self.target, young, self.hold_budget.servo_response_steps,
                                              cp.servo_max_strain_rate * self.platens.height)

    def relax(self, creep_time, safe_point=None, resume=None):
        """Run DEM steps until equilibrium at the held load (the kernel's loop,
        :func:`grainfrac_yade.kernel.held_relaxation.relax_held`, on :class:`CreepHold`); False (and failed) at
        collapse (its ``CollapseWatch``, checked every ``creep.check_period`` steps), past the strain cap, or if
        equilibrium does not come within the hold's budget (``creep.max_relaxation_steps``, or
        ``creep.max_relaxation_crossings`` wave crossings where longer: :attr:`hold_budget`).

        ``safe_point(counters)``: called before each check's DEM steps but the first (the state is
        complete there; the caller checkpoints if one is due); ``resume``: such counters, to go on
        from them (the scene and the servo came back with the checkpoint)."""
        cp = self.params.creep
        done = 0 if resume is None else int(resume["done"])
        self.last_relaxation_steps = done
        watch = collapse_watch(cp, self.platens.axial_strain(), (resume or {}).get("collapse"))
        end = relax_held(CreepHold(self, creep_time), self.hold_budget.max_relaxation_steps, cp.check_period,
                         watch=watch, collapse_stress_ratio=cp.collapse_stress_ratio, done=done, safe_point=safe_point)
        if end.outcome == EQUILIBRIUM:
            return True
        if end.outcome == COLLAPSE:
            self.failed, self.failure_reason = True, end.reason
        elif end.outcome == BUDGET:
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
                "inter": bond_is_inter(self.scene)[idx]}

    def run_event_clock(self, resume=None):
        """Event clock loop; ``resume``: its counters at a checkpoint (the clock is restored with it)."""
        if resume is None:
            self.clock = EventClock(self.params.stress_corrosion.max_strength_loss_fraction,
                                    self.params.stress_corrosion.creep_time_limit)
        try:
            self.n_events = event_clock_loop(self, self.corr, self.clock, resume)
        except NumericalFailure:
            self.n_events = self.clock.n_events   # the events before it: the loop's own count ends with it
            raise

    def run_paper_clock(self, resume=None):
        """Paper clock loop; ``resume``: its counters at a checkpoint (the clock is restored with it).
        Needs a dynamic engine (Eq. 8 measures the unbalanced force)."""
        require_dynamic(self.params, "the paper clock (its unbalanced force, Eq. 8)")
        sc = self.params.stress_corrosion
        if resume is None:
            self.clock = PaperClock(sc.dt_min, sc.dt_max, unbalanced_threshold(sc))
        creep = dataclasses.replace(self.params.creep, max_relaxation_steps=self.hold_budget.max_relaxation_steps)
        paper_clock_loop(self, self.corr, self.clock, self.params.stress_corrosion, creep, resume)
        self.n_events = int(np.sum(self.break_time > 0))

    def safe_point(self, phase, loop):
        """A point between DEM steps where the driver's state is complete (``phase``: "loading" (in the
        ramp), "ramp" (its end), "event", "relaxation" (inside the relaxation after an event-clock creep step),
        "paper"; ``loop``: the ramp's or the clock loop's counters):
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
        if self.vtk_folder is not None and self.vtk_times:
            due, self.vtk_times = due_times(self.vtk_times, creep_time)
            if due:
                self.write_vtk(creep_time)
            if len(due) > 1:   # the clock jumped over several requested times: one frame holds them all
                self.vtk_merged.append({"requested_s": due, "frame_s": creep_time})
                self.progress(merged_frame_note(due, creep_time))
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
                self.consolidation = self.engine.consolidate(self.scene, self.platens, self.confinement.stress, self.params)
                self.failure_reason = broken_apart_reason(self.scene, self.confinement.stress, "no creep test")
                if self.failure_reason:   # no specimen left to load: neither a lifetime nor a survival
                    self.failed_before_test = True
                    self.count_loading_cracks()
                    self.progress(self.failure_reason)
                    return self
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
                    self.scene.run(self.hold_budget.max_relaxation_steps)
                    self.check_failure()
                self.record(0.0, self.servo.stress)
                return self
            self.corr = self.engine.stress_corrosion(self.scene, self.params.stress_corrosion)
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

    The scene is built as for a new run, then replaced by the checkpoint's (the engine's
    ``restore_checkpoint``) and the driver's state is restored (:func:`restore`).  GrainfracError if the folder holds
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
