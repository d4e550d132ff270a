"""Explicit dynamic relaxation of the static network where the static statuses do not settle (pure numpy).

Where a held-load regain gives out (no set of frictional contact statuses settles, :mod:`.solver`), the specimen
is relaxed with inertia instead, as YADE would relax it, but on the static engine's own network: the same nodes,
constant-strain triangles, bonds, rows and contact law, small strain, in numpy.  Central differences on

    M a = f_ext - f_int(u, history),     f damped by Cundall's non-viscous rule f_i (1 - D sign(f_i v_i)),

M lumped (each body's mass and, for rigid cells, its inertia about its node: the grain model's
``masses_and_step``, with ``numerics.density_scale``), the step ``numerics.timestep_safety`` x 2 / omega_max
(omega_max^2 bounded by the largest row sum of M^-1 |K| of the intact tangent, Gershgorin).  Every step evaluates
the contact law of :mod:`.contacts` at the current displacements: intact bonds linear, broken at paper Eq. 4-5 as
soon as they reach it (JCFpm's broken state, :func:`.contacts.break_state`; with saw-tooth softening a bond takes
its next tooth there first, :mod:`.teeth`; with face failure the face's resultant is checked and its intact bonds break
together, :mod:`.face_failure`); broken contacts compression only,
with the residual friction by the return mapping from the last step (:func:`.contacts.trial_status`).

The platens hold the target stress through the creep protocol's servo (closing speed (target - stress) x H /
(E x ``creep.servo_response_steps`` x dt), within ``creep.servo_max_strain_rate`` x H), and the protocol's own
criteria decide, checked every ``creep.check_period`` steps (:func:`grainfrac_yade.kernel.equilibrium.relaxed`):

* **at rest**: mean resultant force on the nodes the platens do not drive over the mean intact bond force below
  ``creep.equilibrium_tolerance``, the held stress within ``creep.stress_tolerance``.  The static equilibrium is
  then solved at the closure reached, from the relaxed broken set and statuses, and the static regain goes on
  from there; where that gives out too, the dynamics go on, and the next such take-back waits 2^k checks after
  the k-th that gave out (each costs a static solve that gives out: 1.3 CPU s on 10 x 20 mm fem cells, where the
  dynamics cost 0.3 ms per step);
* **collapse**: the servo saturated closing while the axial strain grows by ``creep.collapse_strain_increment``
  with the stress below ``creep.collapse_stress_ratio`` x the target
  (:class:`grainfrac_yade.kernel.held_relaxation.CollapseWatch`);
* **no equilibrium within the budget** (``creep.max_relaxation_steps`` / ``_crossings``): the held load is lost,
  the creep protocol's rule for a platen that cannot hold it.

Inertia is thus simulated only where the static path cannot go on, and a run stays bit-for-bit repeatable (numpy
in a fixed order, no YADE).  ``numerics.static_relaxation = "inertial"`` (:data:`.damped.PATHS`).
"""
from __future__ import annotations

import math
import time

import numpy as np

from ...errors import NumericalFailure
from ...grains import model_of
from ...layout import bond_properties
from ...kernel import held_relaxation as held
from ...kernel.held_relaxation import HeldRelaxing, collapse_watch, relax_held
from ...kernel.servo import ServoLaw
from ...wave import hold_budget, scene_density
from . import contacts as cl
from .cascade import Path, Record
from .damped import Relaxation, RelaxingPath, relative_force
from .face_failure import BondFailure
from .failure import COLLAPSE, FailureRule
from .solver import Equilibrium, State

#: Why an inertial relaxation ended in a failure (the creep protocol's words for a load the platens cannot hold).
LOST_LOAD = "no equilibrium at the held load within the relaxation budget"
#: Smallest axial strain taken for the secant modulus that sets the servo's gain and the wave-crossing budget [1]
#: (the creep protocol's floor).
STRAIN_FLOOR = 1e-6


def dof_masses(specimen, params, layout, net) -> np.ndarray:
    """(ndof,) the mass on each translation dof and the inertia on each rotation dof of the static network
    ``net`` [kg, kg m^2]: the grain model's bodies (``masses_and_step``: density x ``numerics.density_scale``,
    the step floor if set), rigid cells' inertia about their network node."""
    props = bond_properties(specimen, layout, params)
    body_pos = np.column_stack([net.node_pos, np.full(len(net.node_pos), 0.5 * specimen.thickness)])
    mass, inertia, _ = model_of(layout).masses_and_step(specimen, params, layout, props, body_pos)
    inertia = np.asarray(inertia, float)
    inertia = inertia[:, 2] if inertia.ndim == 2 else inertia
    m = np.zeros(net.ndof)
    for col, value in ((0, mass), (1, mass), (2, inertia)):
        ok = net.dofs[:, col] >= 0
        m[net.dofs[ok, col]] = np.asarray(value, float)[ok]
    if np.any(m <= 0) or not np.all(np.isfinite(m)):
        raise ValueError("inertial relaxation: every dof needs a positive, finite mass")
    return m


def critical_step(eq: Equilibrium, masses: np.ndarray) -> float:
    """2 / omega_max [s] of the intact network, omega_max^2 bounded by the largest row sum of M^-1 |K| (Gershgorin)."""
    m = eq.net.n_bonds
    k = Equilibrium.tangent(eq, np.full(m, cl.INTACT), np.ones(m), np.zeros(m))
    rows = np.asarray(abs(k).sum(axis=1)).ravel()
    return 2.0 / math.sqrt(float((rows / masses).max()))


def damped_step(u: np.ndarray, v: np.ndarray, f: np.ndarray, inv_m: np.ndarray, dt: float, damping: float) -> None:
    """One central-difference step in place: Cundall's non-viscous damping f_i (1 - D sign(f_i v_i)) on the
    unbalanced force ``f`` [N] (``f`` is overwritten), then v += dt f / m, u += dt v (``inv_m`` 1/m, 0 on driven
    dofs).  Released from rest at u_0 against a spring, a dof swings past its equilibrium to
    -u_0 sqrt((1 - D) / (1 + D)) (work (1 - D) k u_0^2 / 2 gained on the way in, (1 + D) k u_1^2 / 2 lost on the
    way out)."""
    f *= 1.0 - damping * np.sign(f * v)
    v += dt * f * inv_m
    u += dt * v


class HeldServo(ServoLaw):
    """The creep protocol's stress servo on the static network's platen closure (module doc): the kernel's servo
    law (:class:`grainfrac_yade.kernel.servo.ServoLaw`) at the dynamics' step; its :attr:`watch` the collapse
    criterion."""

    def __init__(self, target: float, gain: float, max_speed: float, creep, strain: float):
        super().__init__(float(target), float(gain), float(max_speed))
        self.stress_tolerance = creep.stress_tolerance
        #: the creep protocol's collapse criterion from the strain ``strain`` on (None where it is off)
        self.watch = collapse_watch(creep, strain)

    def speed(self, stress: float, dt: float) -> float:
        """The closing speed [m/s] for the measured ``stress`` [Pa] (and the clip bookkeeping)."""
        return self.command(stress, dt)

    def held(self, stress: float) -> bool:
        """The held stress within ``creep.stress_tolerance`` of the target (the rest criterion's second half)."""
        return abs(stress - self.target) < self.stress_tolerance * self.target

    def lost(self, stress: float) -> bool:
        """Never: a held load is lost by the collapse watch or the budget."""
        return False


class FixedPlatens:
    """The platens held where they are (displacement control: the UCS path, a ramp): no servo; the load is lost
    once the platen stress falls below ``stop_below`` [Pa] (the test's post-peak rule, as the protocol gave it to
    the scene; None: never)."""

    watch = None

    def __init__(self, stop_below):
        self.stop_below, self.stress = (None if stop_below is None else float(stop_below)), 0.0

    def speed(self, stress: float, dt: float) -> float:
        self.stress = stress
        return 0.0

    def held(self, stress: float) -> bool:
        return True

    def lost(self, stress: float) -> bool:
        return self.stop_below is not None and stress < self.stop_below


class InertialRelaxation:
    """Explicit dynamics of one static network under a held platen stress (module doc).  ``masses``: (ndof,)
    [kg, kg m^2]; ``params``: the run's parameters (numerics and creep)."""

    def __init__(self, eq: Equilibrium, masses: np.ndarray, params):
        self.eq, self.net, self.params = eq, eq.net, params
        self.masses = np.asarray(masses, float)
        self.dt = params.numerics.timestep_safety * critical_step(eq, self.masses)
        cp = params.creep
        self.damping = cp.relaxation_damping if cp.relaxation_damping > 0 else params.numerics.damping
        self.density = scene_density(params)
        self._intact_modulus = None
        #: the path's saw-tooth softening (:class:`.teeth.BondTeeth`, set by :func:`.paths.path_for`); None: brittle
        self.teeth = None
        #: the path's failure criterion (:mod:`.face_failure`, set by :func:`.paths.path_for`): each bond's own here
        self.failure = BondFailure(eq.net)

    def budget(self, state: State):
        """The creep protocol's :class:`~grainfrac_yade.wave.HoldBudget` of a relaxation from ``state`` (in this
        network's steps; its wave crossing from the state's secant modulus, :meth:`modulus`)."""
        return hold_budget(self.params.creep, self.net.height, self.modulus(state), self.density, self.dt)

    def servo(self, state: State, target: float) -> HeldServo:
        """The creep protocol's servo holding ``target`` [Pa] from ``state`` (its gain from the state's secant
        modulus and the budget's servo response)."""
        net, cp = self.net, self.params.creep
        gain = net.height / (self.modulus(state) * self.budget(state).servo_response_steps)
        return HeldServo(target, gain, cp.servo_max_strain_rate * net.height, cp, state.closure / net.height)

    def modulus(self, state: State) -> float:
        """Secant axial modulus of ``state`` [Pa] (the intact one where it carries no stress)."""
        young = max(state.stress, 0.0) / max(state.closure / self.net.height, STRAIN_FLOOR)
        return young if young > 0 else self.intact_modulus()

    def relax(self, state: State, control, jt: np.ndarray, jc: np.ndarray, take_back=None):
        """Relax ``state`` (a converged static state) under ``control`` (:class:`HeldServo` or
        :class:`FixedPlatens`) with the current strengths ``jt``, ``jc`` [Pa], by the kernel's held-load loop
        (:func:`grainfrac_yade.kernel.held_relaxation.relax_held`, on :class:`InertialMotion`; the last chunk ends at
        the budget).  ``take_back(state) -> (state, failure reason or None) | None``: the static equilibrium from a
        relaxed dynamic state (None where it gives out: the dynamics go on, the next take-back 2, 4, 8, ... checks
        later).  Returns (state, failure reason or None, steps, take-backs that gave out, bonds broken); with fixed
        platens the reason is :data:`LOST_LOAD` once the stress fell below the control's limit, and at the end of
        the budget the relaxed state is taken back if it can be (as a YADE stint's)."""
        cp = self.params.creep
        budget = self.budget(state)
        motion = InertialMotion(self, state, control, jt, jc, take_back)
        end = relax_held(motion, budget.max_relaxation_steps, cp.check_period, watch=control.watch,
                         collapse_stress_ratio=cp.collapse_stress_ratio, clip_to_budget=True)
        steps, gave_out = end.steps, end.gave_out

        def ended(state_, reason):
            return state_, reason, steps, gave_out, int(state_.broken.sum()) - motion.broken0

        if end.outcome == held.EQUILIBRIUM:
            return ended(*motion.back)
        if end.outcome == held.COLLAPSE:
            return ended(motion.now(), COLLAPSE)
        last = motion.now()
        if end.outcome == held.BUDGET and isinstance(control, FixedPlatens) and take_back is not None:
            back = take_back(last)
            if back is not None:
                return ended(*back)
        return ended(last, LOST_LOAD)

    def intact_modulus(self) -> float:
        """The intact specimen's axial modulus dS/d(strain) [Pa] (the servo's gain and the wave-crossing budget where
        the held state carries no stress to take a secant from)."""
        if self._intact_modulus is None:
            fresh = Equilibrium(self.net, reuse_factor=False)     # the path's kept factor stays as it is
            self._intact_modulus = float(fresh.response(fresh.initial(0.0))[3] * self.net.height)
        return self._intact_modulus

    # ------------------------------------------------------------------ helpers
    def _rows(self, broken):
        gn, gt = self.eq.force_rows(broken)
        return gn.T.tocsr(), gt.T.tocsr()

    def _state(self, closure, u, broken, status, sign, s_p, fn, fs, stress, mode) -> State:
        if not (np.all(np.isfinite(u)) and math.isfinite(stress)):
            raise NumericalFailure("inertial relaxation: the motion became NaN or infinite (a step beyond the "
                                   "critical one?)")
        return State(float(closure), u.copy(), broken.copy(), status.copy(), sign.copy(), s_p.copy(), fn.copy(),
                     fs.copy(), float(stress), mode.copy())


class InertialMotion(HeldRelaxing):
    """The explicit dynamics of one relaxation (:meth:`InertialRelaxation.relax`) as the kernel's held-load loop
    drives them (:class:`~grainfrac_yade.kernel.held_relaxation.HeldRelaxing`): central-difference steps of the
    static network from ``state`` at rest under ``control`` with strengths ``jt``, ``jc`` [Pa]; at rest by the
    relative unbalanced force on the free dofs and the held stress; taken back by ``take_back`` (module doc)."""

    def __init__(self, dynamics: "InertialRelaxation", state: State, control, jt, jc, take_back):
        self.dyn, self.net, self.eq = dynamics, dynamics.net, dynamics.eq
        self.control, self.servo, self.jt, self.jc, self.take_back = control, control, jt, jc, take_back
        self.u, self.v = state.u.copy(), np.zeros(self.net.ndof)
        self.closure = state.closure
        self.broken, self.status, self.sign = state.broken.copy(), state.status.copy(), state.sign.copy()
        self.s_p, self.mode = state.s_p.copy(), state.break_mode.copy()
        #: bonds broken when the relaxation began
        self.broken0 = int(self.broken.sum())
        self.inv_m = np.where(self.eq.platen_fixed, 0.0, 1.0 / dynamics.masses)
        self.rows = dynamics._rows(self.broken)
        #: the take-back of the rested state (:meth:`settle`)
        self.back = None

    def advance(self, steps: int) -> None:
        net, eq, control = self.net, self.eq, self.control
        jt, jc, inv_m = self.jt, self.jc, self.inv_m
        plat = np.flatnonzero(eq.platen_fixed)     # the driven dofs by index (the same values as by the mask)
        e_plat = eq.e[plat]
        dt, damping, teeth, failure = self.dyn.dt, self.dyn.damping, self.dyn.teeth, self.dyn.failure
        u, v, broken, s_p, mode = self.u, self.v, self.broken, self.s_p, self.mode
        status, sign, rows, closure = self.status, self.sign, self.rows, self.closure
        for _ in range(steps):
            u[plat] = closure * e_plat
            dn, ds = net.cn @ u, net.ct @ u
            status, sign = cl.trial_status(dn, ds, broken, s_p, net.kn, net.ks, net.tan_residual, status, sign)[:2]
            fn, fs = cl.forces(dn, ds, status, sign, s_p, net.kn, net.ks, net.tan_residual)
            hit = ~broken & failure.failing(fn, fs, jt, jc, broken)
            if hit.any() and teeth is not None:     # saw-tooth softening: the next tooth, the force dropping
                soft = np.flatnonzero(hit)[teeth.softens(hit)]
                if len(soft):
                    teeth.advance(soft, jt, jc)
                    fn[soft], fs[soft] = net.kn[soft] * dn[soft], net.ks[soft] * ds[soft]
                    hit[soft] = False
            if hit.any():
                idx = np.flatnonzero(hit)
                md = failure.modes(fn, fs, jt, jc, broken, idx)
                st, sg, sp = cl.break_state(dn[idx], ds[idx], fs[idx], net.kn[idx], net.ks[idx],
                                            net.tan_residual[idx])
                broken[idx], status[idx], sign[idx], s_p[idx], mode[idx] = True, st, sg, sp, md
                fn[idx], fs[idx] = cl.forces(dn[idx], ds[idx], st, sg, sp, net.kn[idx], net.ks[idx],
                                             net.tan_residual[idx])
                rows = self.dyn._rows(broken)
            s_p = np.where(broken, cl.converged_slip(ds, status, fs, net.ks), s_p)
            r = net.k_grain @ u + rows[0] @ fn + rows[1] @ fs
            stress = eq.reaction_stress(r - eq.f_ext)
            f = eq.f_ext - r
            damped_step(u, v, f, inv_m, dt, damping)
            closure += dt * control.speed(stress, dt)
        self.status, self.sign, self.rows, self.closure, self.s_p = status, sign, rows, closure, s_p
        self.fn, self.fs, self.stress, self.f = fn, fs, stress, f

    def axial_strain(self) -> float:
        return self.closure / self.net.height

    def lost(self) -> bool:
        return self.control.lost(self.stress)

    def balanced(self) -> bool:
        return (relative_force(self.net, self.f, self.fn, self.fs, self.broken) < self.dyn.params.creep.
                equilibrium_tolerance and self.control.held(self.stress))

    def settle(self) -> bool:
        self.back = self.take_back(self.now()) if self.take_back is not None else (self.now(), None)
        return self.back is not None

    def now(self) -> State:
        """The relaxation's state after the last step (NumericalFailure where the motion is not finite)."""
        return self.dyn._state(self.closure, self.u, self.broken, self.status, self.sign, self.s_p, self.fn, self.fs,
                               self.stress, self.mode)


class InertialPath(RelaxingPath):
    """The static path that relaxes with :class:`InertialRelaxation` where the plain static solve gives out
    (``numerics.static_relaxation = "inertial"``): under a held load (a creep hold's regain) with the creep
    protocol's servo, and under displacement control (the UCS path, a ramp) with the platens held where the path
    stood, as a YADE stint of the hybrid engine would (the specimen failing there once the stress falls below
    :attr:`load_loss_ratio` of the relaxation's start: the test's post-peak rule, which the protocol gives the scene,
    :meth:`.strategy.RelaxationHooks.lose_load_below`).  A relaxed state goes back to the static path by the static
    equilibrium at its closure (and, under a held load, the plain regain: :meth:`take_back`).  Relaxations are
    tallied as the overdamped ones (their steps are DEM steps; "unsettled": take-backs that gave out)."""

    def __init__(self, eq: Equilibrium, dynamics: InertialRelaxation, bracket_tol=None):
        super().__init__(eq, None, bracket_tol=bracket_tol)
        self.dynamics = dynamics
        self._in_move = False       # inside a displacement-controlled step: a cascade that gives out is relaxed here
        #: CPU time spent in the relaxations since the run began (a resumed run's included) [s]
        self.cpu_s = 0.0

    def summary_keys(self) -> dict:
        """The relaxations' tally and their CPU time [s] (``static_relaxation_cpu_s``)."""
        return {**super().summary_keys(), "static_relaxation_cpu_s": float(self.cpu_s)}

    def saved_arrays(self) -> dict:
        return {**super().saved_arrays(), "relaxation_cpu_s": np.array([self.cpu_s])}

    def restore_arrays(self, arrays: dict) -> None:
        super().restore_arrays(arrays)
        self.cpu_s = float(np.asarray(arrays.get("relaxation_cpu_s", [0.0]))[0])

    def take_back(self, relaxed: State, target, rule: FailureRule, begin: float):
        """(state, failure reason or None) of the static equilibrium at the relaxed dynamic state's closure, its
        cascade, and under a held ``target`` [Pa] the plain static regain; None where the static statuses do not
        settle there."""
        try:
            state = Path.cascade(self, self.eq.solve(relaxed.closure, relaxed))
            if target is None:
                return state, None
            state, reason = Path.hold(self, state, target, rule)
        except NumericalFailure:
            return None
        if reason is None and rule.collapsed(begin, state.closure, self.net.height):
            reason = COLLAPSE
        return state, reason

    def _relax(self, start: State, target: float, rule: FailureRule, begin: float) -> Relaxation:
        dyn, c0 = self.dynamics, time.process_time()
        state, reason, steps, gave_out, broken = dyn.relax(
            start, dyn.servo(start, target), self.jt, self.jc, lambda s: self.take_back(s, target, rule, begin))
        self.cpu_s += time.process_time() - c0
        return Relaxation(state, reason, begin, steps, gave_out, broken)

    def cascade(self, state, first=None, record=None):
        if self._in_move:
            return Path.cascade(self, state, first, record)
        return super().cascade(state, first, record)

    def step(self, state: State, target=None, max_closure=math.inf):
        """:meth:`.cascade.Path.step`; under displacement control (no ``target``), where the static solve gives out
        the specimen relaxes with inertia at the closure of the last converged state, its breaks one record; if it
        loses the load there ("none": nothing lies ahead) the path ends on the relaxed state."""
        if target is not None:
            return super().step(state, target, max_closure)
        self._in_move = True
        try:
            return super().step(state, None, max_closure)
        except NumericalFailure:
            start = self.last_converged
        finally:
            self._in_move = False
        dyn, c0 = self.dynamics, time.process_time()
        stop = None if self.load_loss_ratio is None else self.load_loss_ratio * start.stress
        state, reason, steps, gave_out, broken = dyn.relax(
            start, FixedPlatens(stop), self.jt, self.jc, lambda s: self.take_back(s, None, FailureRule(0.0),
                                                                                  start.closure))
        self.cpu_s += time.process_time() - c0
        new = np.flatnonzero(state.broken & ~start.broken)
        self.records.append(Record(start.closure, start.stress, state.stress, new.tolist(),
                                   state.break_mode[new].tolist()))
        self.count(Relaxation(state, reason, start.closure, steps, gave_out, broken))
        self.last_converged = state
        # a specimen that lost its load with the platens held has failed: nothing lies ahead on the path (the
        # protocol's rows show the drop and its post-peak rule ends the test)
        return state, "none" if reason else "break"


__all__ = ["FixedPlatens", "InertialPath", "InertialRelaxation", "HeldServo", "damped_step", "dof_masses", "critical_step",
           "LOST_LOAD"]
