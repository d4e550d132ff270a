"""The static engine's scene: :class:`grainfrac_yade.engines.Scene` on the quasi-static core (pure numpy/scipy).

The test protocols (:mod:`grainfrac_yade.protocols`) drive it unchanged; their calls map onto the core so:

* **platens** (:class:`StaticPlatens`): displacement control of the platen closure d (top -d/2, bottom +d/2,
  smooth platens: lateral motion free, :mod:`.network`).  ``set_axial_velocity(v)`` sets the closing speed of
  the load parameter; the closure is v x the load parameter (:attr:`StaticScene.time`).
* **run(n)**: n increments of the load parameter, each of :attr:`StaticScene.dt`: the closure advances by
  v x dt along the sequentially linear path of :class:`.cascade.Path` (to each bond crossing, the most
  overstressed bond broken alone, equilibrium restored at that closure, then every bond at its strength, one at
  a time), so that after each increment no intact bond is beyond its strength (paper Eq. 4-5).
* **equilibrate**: one solve at the current closure, and the cascade of what is then at its strength.
* **steps** counts equilibria solved (:class:`.solver.Counters`); **time** is the load parameter [s]: the time a
  machine closing at the protocol's speed would take to this closure (a UCS history's ``time_s`` therefore
  reads as YADE's DEM time at the same strain).
* **hold_stress(S)** (the creep hold): load control at S from then on (:class:`StaticServo`): ``run(n)`` and
  ``equilibrate`` break what the creep law took to its strength (the cascade at the reached closure) and regain S
  along the path (:meth:`.cascade.Path.hold`, one solve to the held stress, whatever n); a held stress above S (the
  ramp's overshoot) is first unloaded to S.  Where the core's failure rule (:mod:`.failure`) says the specimen
  cannot hold S, the scene stays in the state reached, reports itself out of equilibrium (:meth:`StaticScene.
  unbalanced` infinite) and the servo saturated closing: the protocol's collapse watch or its relaxation budget
  ends the run as a failure (:data:`HOLD_FAILED_UNBALANCED`).
* **confine(sigma_3)**: a constant lateral traction on the side nodes (a dead load, :meth:`.network.StaticNetwork.
  confinement_force`); the isotropic stage is the path to an axial stress sigma_3 (:func:`consolidate`).
* **save / restore**: an ``.npz`` of the core's state (displacements, contact statuses, shear references, forces,
  strengths, counters): the run goes on bit for bit.
* **export_state / scene_from_state** (:mod:`.scene_state`): :class:`grainfrac_yade.engines.SceneState`; the static
  engine keeps each broken contact's shear reference s_p (its plastic slip) in ``bond_slip`` and the closure in the
  platens' dict.
* **cell_motion / bond_shift** (what the VTK series of :mod:`grainfrac_yade.protocols.snapshots` draw): the cells
  and bonds moved by the solved displacements (rigid cells: translation and rotation of their node; fem cells: the
  least-squares rigid motion of their spheres), as YADE's scene draws its bodies.

Where no set of contact statuses settles (frictional contacts with a non-associated slip rule need not have a
unique quasi-static equilibrium) the core raises :class:`~grainfrac_yade.errors.NumericalFailure`: the protocols
end the run as a numerical failure with that reason.  Rough platens are not in the core yet: refused with one
line.  The Brazilian disc's jaws (``attach_jaws``) are those of a disc's scene, :class:`.jaws.DiscScene`: the
jaw cells as prescribed-displacement platens, rough or smooth.  The creep hold follows a law that changes strengths only (a law that changes the
bonds' stiffness, the area law, is refused in one line: :data:`STIFFNESS_LAW_REFUSED`).
"""
from __future__ import annotations

import math

import numpy as np

from .._interface import SceneState
from ...errors import GrainfracError, NumericalFailure
from ...grains import layout_for
from ...layout import bond_properties
from ...vtkio import cluster_rigid_motion
from . import contacts as cl
from .inertial import dof_masses
from .paths import path_for
from .platens import StaticConfinement, StaticPlatens, StaticServo
from .failure import FailureRule
from .network import build_static_network
from .scene_state import SceneStateExchange
from .settings import summary_keys
from .solver import Equilibrium, State, solver_options
from .strategy import RelaxationHooks, SceneRelaxation

#: Fields of the core's converged state that a save keeps (arrays over bonds in canonical order, or scalars).
STATE_FIELDS = ("closure", "u", "broken", "status", "sign", "s_p", "fn", "fs", "stress", "break_mode", "held",
                "iterations")
#: Prefix of the solver's kept state (:meth:`.solver.Equilibrium.factor_state`) in a saved scene's arrays.
FACTOR_PREFIX = "factor_"
#: Name the static engine's parts carry in :meth:`StaticScene.engine_names`.
EQUILIBRIUM_NAME = "StaticEquilibrium"


def load_increment(params) -> float:
    """The load parameter's increment of one solved step [s]: ``ucs.record_strain_increment / ucs.strain_rate``,
    so that a UCS history row is one increment of the path (the path itself finds every bond crossing inside it;
    the increment only sets where rows are written)."""
    return params.ucs.record_strain_increment / params.ucs.strain_rate


#: What :meth:`StaticScene.unbalanced` reports once the failure rule says the held load cannot be regained [N and
#: 1]: no equilibrium exists under it, so the protocol's equilibrium check never passes (its relaxation budget, or
#: its collapse watch first, ends the run as a failure).
HOLD_FAILED_UNBALANCED = math.inf
#: Newton steps of the unloading to a held stress below the ramp's end [1]: along one linear branch the first step
#: lands on it; a status change on the way (a closed contact opening) costs one more each.
MAX_UNLOAD_STEPS = 50
#: The one line that refuses a degradation law that changes the bonds' stiffness on the static engine.
STIFFNESS_LAW_REFUSED = ("static engine: the creep hold follows laws that lower strengths only; this law changes the "
                         "bonds' stiffness (the area law); fix: stress_corrosion.law = \"hillig_charles\", or "
                         "--engine yade")
#: What the command line refuses of a VTK series on the static engine: nothing ("": the series are written, the
#: cells and bonds drawn from the solved displacements by :meth:`StaticScene.cell_motion` and :meth:`StaticScene.
#: bond_shift`, read by :mod:`grainfrac_yade.protocols.snapshots` as on any engine).
VTK_REFUSED = ""


class StaticScene(SceneStateExchange, RelaxationHooks):
    """A specimen's static scene (module doc); bond arrays of the interface in the layout's order.  ``strategy``:
    what it does where the plain static solve gives out (:class:`.strategy.SceneRelaxation`; default the plain one,
    the path relaxing by ``numerics.static_relaxation``)."""

    def __init__(self, specimen, params, layout=None, strategy: SceneRelaxation | None = None):
        self.specimen, self.params = specimen, params
        #: the scene's relaxation strategy (:mod:`.strategy`)
        self.strategy = strategy or SceneRelaxation()
        self.layout = layout or layout_for(specimen, params)
        self.net = build_static_network(specimen, params, self.layout)
        m = self.net.n_bonds
        #: canonical number of each layout bond (the network keeps bonds in a numbering-free order)
        self.canon = np.empty(m, np.int64)
        self.canon[self.net.order] = np.arange(m)
        self.confinement_stress = 0.0
        self.eq = Equilibrium(self.net, **solver_options(params))
        self.path = path_for(self.eq, params, 0.0, self.masses, self.strategy.path_relaxation)
        self.drivers = []
        self._dt = load_increment(params)
        self._time = 0.0
        self._steps_offset = 0
        self.broken = np.zeros(m, bool)
        self.break_mode = np.zeros(m, np.int8)
        self.break_step = np.full(m, -1, np.int64)
        self.state = self.eq.initial(0.0)
        #: the bonds' intact properties in the layout's order (:func:`grainfrac_yade.layout.bond_properties`)
        self.props = bond_properties(specimen, self.layout, params)
        #: the held platen stress [Pa] (:meth:`StaticPlatens.hold_stress`), None under displacement control
        self.hold_target = None
        #: the failure rule's reason once the held stress cannot be regained ("" while it is held)
        self.hold_failure = ""
        #: canonical bonds the creep law took to their failure point, broken at the next solve if the cascade did not
        self.hold_pending = np.zeros(0, np.int64)
        self.hold_rule = FailureRule(params.creep.collapse_strain_increment)
        self.strategy.attach(self)

    @property
    def engine_name(self) -> str:
        """The engine a checkpoint of this scene names (a checkpoint is resumed by the engine that wrote it): its
        strategy's."""
        return self.strategy.engine_name

    # ------------------------------------------------------------------ counters
    @property
    def steps(self) -> int:
        """Equilibria solved so far (bracketing and cascades included)."""
        return self._steps_offset + self.eq.counters.equilibria

    @property
    def time(self) -> float:
        """The load parameter [s] (module doc)."""
        return self._time

    @property
    def dt(self) -> float:
        return self._dt

    @property
    def n_bonds(self) -> int:
        return self.net.n_bonds

    # ------------------------------------------------------------------ advancing
    def _platens(self):
        return next((d for d in self.drivers if isinstance(d, StaticPlatens)), None)

    def run(self, n_steps: int) -> None:
        """``n_steps`` increments of the load parameter, the closure following the platens' speed; under a held
        stress one solve to it, whatever ``n_steps`` (:meth:`hold`)."""
        if self.hold_target is not None:
            self.hold(n_steps)
            return
        pl = self._platens()
        speed = pl.velocity if pl is not None else 0.0
        for _ in range(int(n_steps)):
            self.move_to(self.state.closure + speed * self._dt)
            self._time += self._dt     # only once the increment is solved (a NumericalFailure leaves the last one)

    def move_to(self, closure: float) -> None:
        """Follow the path to ``closure`` [m] (breaks at their crossings, cascades); the bookkeeping synced.  A
        closure behind the current one (opening platens) is solved directly, with the cascade there.  Through the
        strategy (:meth:`.strategy.SceneRelaxation.move`)."""
        self.strategy.move(self, lambda: self._follow(closure))

    def _follow(self, closure: float) -> None:
        if closure >= self.state.closure:
            state = self.path.run_closure(self.state, closure)
        else:
            state = self.path.cascade(self.eq.solve(closure, self.state))
        self._take(state)

    def unbalanced(self, reference: float) -> tuple:
        """(0, 0): a solved static state is in equilibrium (the active-set solution is exact to round-off); infinite
        once the held stress cannot be regained (:data:`HOLD_FAILED_UNBALANCED`)."""
        if self.hold_failure:
            return HOLD_FAILED_UNBALANCED, HOLD_FAILED_UNBALANCED
        return 0.0, 0.0

    def relaxation_damping(self, damping: float) -> None:
        """Ignored: equilibrium is solved, not relaxed (numerics.damping is a dynamic-only setting)."""

    def equilibrate(self, balanced, check_steps: int, max_steps: int):
        """One solve at the current closure and loads, and the cascade of what is at its strength: 1 step."""
        before = self.steps
        if self.hold_target is not None:
            self.hold(1)
        else:
            self._take(self.path.cascade(self.eq.solve(self.state.closure, self.state)))
        return max(1, self.steps - before)

    def hold(self, n_steps: int = 1) -> None:
        """Under the held stress: the cascade of what is at its strength at the reached closure (the bonds handed
        over by the creep law among it), then the path back to the held stress (:meth:`.cascade.Path.hold`, with the
        failure rule of :mod:`.failure`); a stress above it (the ramp's overshoot) unloaded to it first.  Once the
        rule says the load cannot be regained, nothing moves any more (module doc).  Through the strategy
        (:meth:`.strategy.SceneRelaxation.hold`); the creep law's hand-overs are kept until a regain succeeds."""
        self.strategy.hold(self, lambda: self._regain(n_steps))

    def _regain(self, n_steps: int) -> None:
        servo = next((d for d in self.drivers if isinstance(d, StaticServo)), None)
        if not self.hold_failure:
            state = self.path.cascade(self.state)
            for c in self.hold_pending:
                if not state.broken[c]:
                    state = self.path.cascade(state, first=int(c))
            state = self._unload(state, self.hold_target)
            state, reason = self.path.hold(state, self.hold_target, self.hold_rule)
            self._take(state)
            self.hold_pending = np.zeros(0, np.int64)
            self.hold_failure = reason or ""
        if servo is not None:
            servo.count(n_steps)

    def _unload(self, state: State, target: float) -> State:
        """``state`` with its platen stress brought down to ``target`` [Pa] if above it, by Newton steps on the
        tangent response (opening platens break nothing; a cascade is checked after)."""
        for _ in range(MAX_UNLOAD_STEPS):
            if state.stress <= target * (1 + self.path.bracket_tol):
                break
            _, _, _, slope = self.eq.response(state)
            if not slope > 0:
                break
            state = self.eq.solve(state.closure - (state.stress - target) / slope, state)
        return self.path.cascade(state)

    def hand_over(self, indices) -> None:
        """Bonds ``indices`` (layout order) reached their failure point under the creep law: broken at the next
        solve, by the cascade (their strengths are written) or alone if it leaves them intact."""
        self.hold_pending = np.union1d(self.hold_pending, self._idx(indices))

    def _take(self, state: State) -> None:
        if not (math.isfinite(state.stress) and np.all(np.isfinite(state.fn)) and np.all(np.isfinite(state.fs))):
            raise NumericalFailure(f"static equilibrium: a force is NaN or infinite at closure {state.closure:.6g} m")
        new = state.broken & ~self.state.broken
        self.state = state
        if new.any():
            lay = self.net.order[np.flatnonzero(new)]
            self.broken[lay] = True
            self.break_mode[lay] = state.break_mode[np.flatnonzero(new)]
            self.break_step[lay] = self.steps

    # ------------------------------------------------------------------ bonds
    def _idx(self, indices):
        return self.canon if indices is None else self.canon[np.atleast_1d(np.asarray(indices, np.int64))]

    def bond_forces(self, indices=None):
        c = self._idx(indices)
        return self.state.fn[c].copy(), np.abs(self.state.fs[c])

    def bond_stresses(self, indices=None):
        c = self._idx(indices)
        area = self.net.area[c]
        return self.state.fn[c] / area, np.abs(self.state.fs[c]) / area

    def bond_strengths(self, indices=None):
        c = self._idx(indices)
        intact = ~self.state.broken[c]
        return np.where(intact, self.path.jt[c], 0.0), np.where(intact, self.path.jc[c], 0.0)

    def write_bond_strengths(self, indices, tensile, cohesion) -> None:
        c = self._idx(indices)
        self.path.jt[c] = np.broadcast_to(np.asarray(tensile, float), c.shape)
        self.path.jc[c] = np.broadcast_to(np.asarray(cohesion, float), c.shape)

    def break_bonds(self, indices, mode: int) -> None:
        """Break bonds ``indices`` in ``mode``, one at a time in canonical order, equilibrium restored after each
        (JCFpm's broken contact: compression only, residual friction)."""
        state = self.state
        for c in np.sort(self._idx(indices)):
            if not state.broken[c]:
                state = self.path.break_bond(state, int(c), int(mode))
        self._take(state)

    def bond_separated(self, indices) -> np.ndarray:
        c = self._idx(indices)
        return (self.net.cn[c] @ self.state.u) > 0

    def sliding_erasures(self) -> int:
        """None: a static contact is never erased by sliding."""
        return 0

    # ------------------------------------------------------------------ cells, platens, confinement
    def node_positions(self) -> np.ndarray:
        """(n_nodes, 2) current node positions [m] (the network's nodes, cell by cell)."""
        net, u = self.net, self.state.u
        d = np.zeros((len(net.node_pos), 2))
        for col in range(2):
            ok = net.dofs[:, col] >= 0
            d[ok, col] = u[net.dofs[ok, col]]
        return net.node_pos[:, :2] + d

    def cell_positions(self, cells=None) -> np.ndarray:
        """(n, 3) mean position of each cell's nodes [m] (z: the specimen's mid-plane)."""
        pos, cell = self.node_positions(), self.net.node_cell
        n_cells = self.specimen.n_cells
        sums = np.zeros((n_cells, 2))
        np.add.at(sums, cell, pos)
        mean = sums / np.maximum(np.bincount(cell, minlength=n_cells), 1)[:, None]
        out = np.column_stack([mean, np.full(n_cells, 0.5 * self.specimen.thickness)])
        return out if cells is None else out[np.asarray(cells, np.int64)]

    def _nodes_are_cells(self) -> bool:
        """True where every node is a whole cell (rigid cells: one node per cell, with a rotation); False where the
        nodes are the layout's spheres (fem cells: several translating nodes per cell)."""
        cell = self.net.node_cell
        return len(cell) == self.specimen.n_cells and bool(np.array_equal(cell, np.arange(len(cell))))

    def cell_motion(self) -> tuple:
        """((n, 2) positions [m] of the cell centroids, (n,) rotations about z [rad]) from the solved displacements
        (small displacements, as the core solves them): rigid cells their node's translation and rotation dof;
        fem cells the least-squares rigid motion of their spheres weighted by their lumped areas (as YADE's fem
        scene draws them, :func:`grainfrac_yade.vtkio.cluster_rigid_motion`)."""
        net, tess = self.net, self.specimen.tessellation
        pos = self.node_positions()
        if self._nodes_are_cells():
            rot = net.dofs[:, 2]
            angle = np.where(rot >= 0, self.state.u[np.maximum(rot, 0)], 0.0)
            return pos, angle
        lay = self.layout
        weights = getattr(lay, "sphere_area", None)
        weights = np.ones(lay.n_spheres) if weights is None else weights
        return cluster_rigid_motion(lay.sphere_center, pos, lay.sphere_cell, weights, tess.cell_centroid)

    def bond_shift(self, positions) -> np.ndarray:
        """(b, 2) displacement [m] drawn for each bond (layout order): the mean of its two nodes' displacements, i.e.
        of its two cells' translations (rigid cells, read off ``positions`` of :meth:`cell_motion` as YADE's rigid
        scene does) or of its two spheres' (fem cells)."""
        lay = self.layout
        if self._nodes_are_cells():
            cells = lay.sphere_cell[lay.bond_spheres]
            disp = np.asarray(positions)[:, :2] - self.specimen.tessellation.cell_centroid[:, :2]
        else:
            cells = lay.bond_spheres
            disp = self.node_positions() - self.net.node_pos[:, :2]
        return 0.5 * (disp[cells[:, 0]] + disp[cells[:, 1]])

    def attach_platens(self, lateral: str = "free") -> StaticPlatens:
        if lateral != "free":
            raise GrainfracError(f"static engine: platen_lateral = {lateral!r} (rough platens) is not in the static "
                                 "core, whose platens are smooth; fix: platen_lateral = \"free\" or the YADE engine")
        pl = self._platens() or StaticPlatens(self)
        if pl not in self.drivers:
            self.drivers.append(pl)
        return pl

    def attach_jaws(self, loading_arc: float, lateral: str = "fixed"):
        """Refused: the Brazilian jaws go on a disc, whose scene (:class:`.jaws.DiscScene`) has them."""
        raise GrainfracError("Brazilian test: the specimen is not a disc; fix: build it with "
                             "grainfrac_yade.geometry.specimen.build_disc_specimen")

    def confine(self, stress: float) -> StaticConfinement:
        conf = StaticConfinement(self, stress)
        self.drivers.append(conf)
        return conf

    def set_confinement(self, stress: float) -> None:
        """Rebuild the equilibrium with a constant lateral traction ``stress`` [Pa] and re-solve where the scene is."""
        self.confinement_stress = float(stress)
        counters = self.eq.counters
        self.eq = Equilibrium(self.net, confinement=self.confinement_stress, **solver_options(self.params))
        self.eq.counters = counters
        jt, jc, kept = self.path.jt, self.path.jc, self.path.saved_arrays()
        self.path = path_for(self.eq, self.params, self.confinement_stress, self.masses, self.strategy.path_relaxation,
                             self.path.teeth)
        self.path.load_loss_ratio = self.load_loss_ratio
        self.path.jt, self.path.jc = jt, jc
        self.path.restore_arrays(kept)
        self.strategy.attach(self)          # the rebuilt path takes the strategy's settings again (a hand-over size)
        self.state = self.eq.solve(self.state.closure, self.state)

    def summary_keys(self) -> dict:
        """What a run's summary records of the engine: its name and the dynamic-only settings it did not use (and
        what its drivers record, e.g. the Brazilian jaws' largest load on the path)."""
        keys = summary_keys(self.params)
        keys.update(self.path.summary_keys())
        for d in self.drivers:
            if hasattr(d, "summary_keys"):
                keys.update(d.summary_keys())
        keys.update(self.strategy.summary_keys(self))
        return keys

    def engine_names(self) -> list:
        return [EQUILIBRIUM_NAME] + [d.name for d in self.drivers]

    def counts(self) -> dict:
        """Nodes, closed contacts (intact bonds and closed broken ones) and bonds."""
        return {"n_bodies": int(len(self.net.node_pos)), "n_interactions": int(np.count_nonzero(self.state.status
                                                                                                  != cl.OPEN)),
                "n_bonds": self.n_bonds}

    # ------------------------------------------------------------------ state
    def _arrays(self) -> dict:
        out = {"state_" + k: np.asarray(getattr(self.state, k)) for k in STATE_FIELDS}
        out.update(jt=self.path.jt, jc=self.path.jc, broken=self.broken, break_mode=self.break_mode,
                   break_step=self.break_step, time=np.float64(self._time), steps=np.int64(self.steps),
                   confinement=np.float64(self.confinement_stress), n_bonds=np.int64(self.n_bonds),
                   hold_target=np.float64(math.nan if self.hold_target is None else self.hold_target),
                   hold_failure=np.str_(self.hold_failure), hold_pending=self.hold_pending)
        out.update(self.path.saved_arrays())
        out.update(self.strategy.saved_arrays())
        return out

    def save(self, path) -> None:
        """An ``.npz`` of the core's state, strengths, bookkeeping and counters (exact doubles), and what rebuilds
        the solver's kept factor (:meth:`.solver.Equilibrium.factor_state`: its answers depend on it at round-off).
        Saving only reads: a run that saves goes on as one that does not, and a restored one as both."""
        arrays = self._arrays()
        arrays.update({FACTOR_PREFIX + k: v for k, v in self.eq.factor_state().items()})
        with open(path, "wb") as fh:
            np.savez(fh, **arrays)

    def restore(self, path) -> None:
        """Replace this scene's state by the one :meth:`save` wrote (same specimen and parameters)."""
        with np.load(path) as data:
            a = {k: data[k] for k in data.files}
        if int(a["n_bonds"]) != self.n_bonds:
            raise GrainfracError(f"{path}: a static scene of {int(a['n_bonds'])} bonds, not {self.n_bonds}; fix: "
                                 "start the run again with --overwrite")
        if float(a["confinement"]) != self.confinement_stress:
            self.set_confinement(float(a["confinement"]))
        values = {k: a["state_" + k] for k in STATE_FIELDS}
        for k in ("closure", "stress"):
            values[k] = float(values[k])
        for k in ("held", "iterations"):
            values[k] = int(values[k])
        self.state = State(**values)
        self.path.jt, self.path.jc = a["jt"].copy(), a["jc"].copy()
        self.path.restore_arrays(a)         # before the factor: the bonds' softened stiffness is in its tangent
        self.eq.restore_factor_state({k[len(FACTOR_PREFIX):]: v for k, v in a.items() if k.startswith(FACTOR_PREFIX)})
        self.broken, self.break_mode, self.break_step = a["broken"].copy(), a["break_mode"].copy(), a["break_step"].copy()
        self._time = float(a["time"])
        self._steps_offset = int(a["steps"]) - self.eq.counters.equilibria
        target = float(a["hold_target"]) if "hold_target" in a else math.nan
        self.hold_target = None if math.isnan(target) else target
        self.hold_failure = str(a["hold_failure"]) if "hold_failure" in a else ""
        self.hold_pending = a["hold_pending"].astype(np.int64) if "hold_pending" in a else np.zeros(0, np.int64)
        self.strategy.restore_arrays(a)

    def checkpoint_state(self) -> dict:
        return {"n_bodies": int(len(self.net.node_pos)), "n_bonds": self.n_bonds, "engine": self.engine_name}

    def restore_checkpoint(self, where, scene_file, saved: dict, arrays: dict, confinement=None) -> None:
        if saved.get("engine") != self.engine_name or saved["n_bonds"] != self.n_bonds:
            raise GrainfracError(f"{where}: checkpoint of another scene (engine {saved.get('engine', 'yade')!r}, "
                                 f"{saved['n_bonds']} bonds; rebuilt: {self.engine_name}, {self.n_bonds}); fix: resume it with the "
                                 "engine that wrote it, or start the run again with --overwrite")
        try:
            self.restore(scene_file)
        except (OSError, ValueError, KeyError, EOFError) as exc:
            raise GrainfracError(f"{scene_file}: the checkpoint's static scene is unreadable ({type(exc).__name__}: "
                                 f"{exc}); fix: start the run again with --overwrite") from None
        if confinement is not None and confinement.stress != self.confinement_stress:
            confinement.apply()
        self.broken, self.break_mode, self.break_step = (np.array(arrays[k]) for k in ("broken", "break_mode",
                                                                                        "break_step"))

    def masses(self):
        """(ndof,) masses and inertias of the network's dofs (:func:`.inertial.dof_masses`), for a path that moves
        with inertia."""
        return dof_masses(self.specimen, self.params, self.layout, self.net)


def build_scene(specimen, params, layout=None) -> StaticScene:
    """The static scene of ``specimen`` (rigid or fem cells, as ``resolution.grain_model`` builds its layout)."""
    return StaticScene(specimen, params, layout)


def scene_from_state(specimen, params, state: SceneState, layout=None) -> StaticScene:
    """A static scene of ``specimen`` in ``state`` (:meth:`StaticScene.export_state` of this or another engine),
    equilibrium solved there."""
    scene = StaticScene(specimen, params, layout)
    scene.apply_state(state)
    return scene


def consolidate(scene: StaticScene, platens, stress: float, params) -> dict:
    """The isotropic stage of a confined test: the path under the lateral traction ``stress`` [Pa] until the axial
    stress equals it (sigma_1 = sigma_3).  The protocol's keys: steps it took, whether it was reached, the axial
    stress there."""
    before = scene.steps
    state, reason = scene.path.hold(scene.state, stress, FailureRule(0.0))
    scene._take(state)
    return {"consolidation_steps": scene.steps - before, "consolidated": not reason,
            "consolidation_axial_stress_pa": float(state.stress)}
