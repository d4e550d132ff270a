"""A static scene's relaxation strategy: what the scene does where its plain static solve gives out, and the small
public interface through which a strategy reads and changes the scene (pure numpy).

A static scene (:class:`.scene.StaticScene`) advances by two solves: a displacement-controlled step along the
sequentially linear path (:meth:`~.scene.StaticScene.move_to`) and the regain of a held platen stress
(:meth:`~.scene.StaticScene.hold`).  Each runs through the scene's strategy (:class:`SceneRelaxation`), which is
given the plain solve and decides what happens where it gives out.  The plain strategy (this module's
:class:`SceneRelaxation`) just runs it; its path's own relaxation (``numerics.static_relaxation``,
:data:`.paths.PATHS`: none, overdamped, inertial) acts inside it.  Another strategy (the hybrid engine's dynamic
stints on another engine, :mod:`grainfrac_yade.engines.hybrid.stints`) catches the path's giving out and relaxes
elsewhere, then puts what it reached back through :class:`RelaxationHooks`, the scene's hooks:

* reading: :meth:`~RelaxationHooks.last_converged` (where the path stood when it gave out),
  :meth:`~RelaxationHooks.attached_platens`, :attr:`~RelaxationHooks.height`, :meth:`~RelaxationHooks.failure_modes`,
  the scene's ``state`` (closure, stress), ``hold_target``, ``steps``, ``broken`` and ``export_state``;
* changing: :meth:`~RelaxationHooks.limit_cascade` (a cascade above a number of bonds gives out as
  :class:`.cascade.LargeCascade`), :meth:`~RelaxationHooks.adopt` (a solved core state),
  :meth:`~RelaxationHooks.take_hand_overs` (the creep law's hand-overs not yet broken, taken from the scene),
  :meth:`~RelaxationHooks.add_steps` (steps run elsewhere, in the step counter that ``break_step`` reads),
  :meth:`~RelaxationHooks.take_relaxed_state` (a relaxed state of another engine, taken back whole),
  :meth:`~RelaxationHooks.take_breaks` (the bonds another engine broke, each broken alone here),
  :meth:`~RelaxationHooks.take_lost_load` (a relaxation elsewhere in which the load was lost) and
  :meth:`~RelaxationHooks.fail_hold` (the held load cannot be regained).

The post-peak rule under displacement control (a relaxation with the platens held ends as the specimen's failure
once the stress falls below a ratio of its start) is the test protocol's: it gives it to the scene
(:meth:`~RelaxationHooks.lose_load_below`), and a strategy or a path reads it as :attr:`~RelaxationHooks.
load_loss_ratio` (None: never).
"""
from __future__ import annotations

import dataclasses

import numpy as np

from ...errors import NumericalFailure
from .cascade import LargeCascade


class SceneRelaxation:
    """The plain strategy: each solve runs as the path makes it (its own relaxation inside); the scene's engine is
    ``"static"``.  A strategy overrides :meth:`move` and :meth:`hold` (and its records); :attr:`path_relaxation`
    names the path it wants (None: ``numerics.static_relaxation``)."""

    #: The engine a scene with this strategy is (its summary's and its checkpoint's ``engine``).
    engine_name = "static"
    #: The static path's relaxation (a key of :data:`.paths.PATHS`); None: ``numerics.static_relaxation``.
    path_relaxation = None

    def attach(self, scene) -> None:
        """Called once the scene is built (its path made)."""

    def move(self, scene, solve) -> None:
        """A displacement-controlled step: ``solve()`` follows the path to the closure asked for."""
        solve()

    def hold(self, scene, solve) -> None:
        """The held stress's regain: ``solve()`` regains it (and counts the servo's steps)."""
        solve()

    def summary_keys(self, scene) -> dict:
        """What the strategy adds to the scene's summary keys (after the path's and the drivers')."""
        return {}

    def saved_arrays(self) -> dict:
        """What a saved scene keeps of the strategy (arrays by name)."""
        return {}

    def restore_arrays(self, arrays: dict) -> None:
        """The strategy's state from a saved scene's arrays (:meth:`saved_arrays`; absent keys: a fresh state)."""


class RelaxationHooks:
    """The hooks of :class:`.scene.StaticScene` that a strategy uses (module doc): its ``net``, ``path``,
    ``state``, ``canon`` and bond bookkeeping read and written here only."""

    #: the test's post-peak rule under displacement control (:meth:`lose_load_below`), None: none given
    load_loss_ratio = None

    def lose_load_below(self, ratio) -> None:
        """Under displacement control, a relaxation with the platens held (where the static path gives out) ends as
        the specimen's failure once its platen stress falls below ``ratio`` x the stress it started from (None:
        never): the test protocol's post-peak rule (the UCS test's ``ucs.stop_stress_ratio``)."""
        self.load_loss_ratio = None if ratio is None else float(ratio)
        self.path.load_loss_ratio = self.load_loss_ratio

    @property
    def height(self) -> float:
        """The specimen's height between the platens [m]."""
        return self.net.height

    def attached_platens(self):
        """The platens attached to the scene (:class:`.platens.StaticPlatens`), None before ``attach_platens``."""
        return self._platens()

    def limit_cascade(self, bonds) -> None:
        """A cascade that breaks more than ``bonds`` bonds at one closure gives out as
        :class:`.cascade.LargeCascade` (its state the one after the last of them); None: never."""
        self.path.max_cascade = bonds

    def last_converged(self):
        """The last converged core state of the path (where a solve that gave out last stood), None before one."""
        return self.path.last_converged

    def adopt(self, state) -> None:
        """``state`` (a solved core state of this scene) as the scene's, the bonds it broke marked at the current
        step count; NumericalFailure if a force is not finite."""
        self._take(state)

    def failure_modes(self, state, indices) -> np.ndarray:
        """The mode each bond ``indices`` (layout order) would break in at ``state`` (a core state)."""
        _, mode = self.path.ratios(state)
        return mode[self.canon[np.asarray(indices, np.int64)]]

    def take_hand_overs(self) -> np.ndarray:
        """The bonds (layout order, sorted) the creep law handed over that are not broken yet; the scene forgets
        them (whoever takes them breaks them)."""
        pending = np.setdiff1d(self.net.order[self.hold_pending], np.flatnonzero(self.broken))
        self.hold_pending = np.zeros(0, np.int64)
        return pending

    def add_steps(self, steps: int) -> None:
        """``steps`` run elsewhere (another engine's DEM steps) added to the step counter (:attr:`steps`)."""
        self._steps_offset += int(steps)

    def fail_hold(self, reason: str) -> None:
        """The held load cannot be regained, for ``reason``: the scene stays where it is, out of equilibrium
        (as the failure rule leaves it)."""
        self.hold_failure = reason

    def take_relaxed_state(self, state) -> None:
        """A relaxed :class:`~grainfrac_yade.engines.SceneState` of another engine as this scene's: nodes, broken
        set and strengths as it left them, each broken contact's shear reference from its shear force (s_p = du_s -
        F_s / k_s along the static tangent, :mod:`.contacts`), the static equilibrium solved there and its cascade
        (counters and load parameter as they are here).  With fem cells a relaxed YADE state is a static equilibrium
        of the same model (the hand-over check: 2e-10), so the solve starts settled.  NumericalFailure where it does
        not settle (LargeCascade where its cascade grows): the scene is then left as it was."""
        saved = (self.state, self.path.jt.copy(), self.path.jc.copy(), self.broken.copy(), self.break_mode.copy(),
                 self.break_step.copy(), self._steps_offset)
        try:
            net = self.net
            _, tangent = self._bond_frame()
            fs = (np.asarray(state.bond_shear_force) * tangent).sum(1)[net.order]
            ds = net.ct @ self.displacements(state)
            broken = np.asarray(state.bond_broken, bool)[net.order]
            slip = np.empty(self.n_bonds)
            slip[net.order] = np.where(broken, ds - fs / net.ks, 0.0)
            back = dataclasses.replace(state, bond_slip=slip, steps=self.steps, time=self._time, platens=None)
            self.apply_state(back)
            self._take(self.path.cascade(self.state))
        except (NumericalFailure, LargeCascade):
            (self.state, self.path.jt, self.path.jc, self.broken, self.break_mode, self.break_step,
             self._steps_offset) = saved
            raise

    def take_breaks(self, broken, break_step, break_mode) -> None:
        """The bonds broken elsewhere (layout-order arrays of another engine's scene: ``broken``, the step each
        broke at, its mode) and not here, in the order they broke (ties: canonical order), into the current
        state, each broken alone and the static equilibrium restored at the same closure
        (:meth:`.cascade.Path.break_bond`), then the static cascade: the static model keeps its own state and
        contact statuses, the other engine decides which bonds break.  What was reached before a solve gave out is
        kept (and the error raised)."""
        new = np.flatnonzero(np.asarray(broken) & ~self.broken)
        order = np.lexsort((self.canon[new], np.asarray(break_step)[new]))
        state = self.state
        try:
            for k in new[order]:
                state = self.path.break_bond(state, int(self.canon[k]), int(break_mode[k]))
            state = self.path.cascade(state)
        finally:
            self._take(state)

    def take_lost_load(self, broken, break_mode, closure_change: float, stress: float, steps: int) -> None:
        """A relaxation elsewhere in which the load was lost: the bonds it broke (layout-order ``broken`` and
        ``break_mode``) marked broken at the current step count, the platens' closure moved by ``closure_change``
        [m] and their stress ``stress`` [Pa] as it left them (the run's last row shows the load the specimen kept),
        then its ``steps`` added to the step counter.  The core state is otherwise left as it was."""
        new = np.asarray(broken) & ~self.broken
        self.broken[new], self.break_mode[new] = True, np.asarray(break_mode)[new]
        self.break_step[new] = self.steps
        self.state = dataclasses.replace(self.state, closure=self.state.closure + closure_change, stress=stress)
        self._steps_offset += int(steps)
