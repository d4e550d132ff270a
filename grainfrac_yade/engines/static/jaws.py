"""The Brazilian disc's jaws on the static engine, and the levers of the Brazilian test (pure numpy/scipy).

**The jaws are cells of the disc, as on YADE** (:mod:`grainfrac_yade.protocols.brazilian`; YADE's
``engines/yade/jaws.py``): the cells whose rim arc overlaps an arc of ``loading_arc`` about the top (bottom) end
of the vertical diameter move together along it, rotations blocked, and across it fixed (``lateral = "fixed"``,
rough steel jaws) or free (``"free"``, smooth).  There is no jaw-cell contact law on either engine: the load goes
into the disc through the same Table 2 bonds as everywhere else.  In the static core every node of a top (bottom)
jaw cell is a prescribed-displacement boundary of the equilibrium, as the UCS platens' cells are
(:mod:`.network`): u_y = -d/2 (+d/2) for the jaw closure d, rotation 0, and with fixed jaws u_x = 0 (a
:class:`JawEquilibrium`); with free jaws u_x is free, one lateral dof pinned against the rigid translation
(:mod:`.solver`).  On YADE the same cells are driven at a constant speed through explicit dynamics; here the
closure is followed along the sequentially linear path of :class:`.cascade.Path` (bonds broken one at a time at
their crossings, a snap-back not followed: the load drops at fixed closure through the cascade).  No loading
rate enters the static strength: the closing speed only labels the load parameter (``time_s``).

Measures, as YADE's jaws read them: the load P = the mean of the two jaws' reactions along the diameter
(:meth:`.solver.Equilibrium.platen_stress` x D x t, the network's width being D), the diametral strain = closure
/ D, the horizontal strain = -(change of the mean x of the nodes of the cells at the right end of the horizontal
diameter minus that of the left end) / D (every node of those cells, as YADE averages their bodies).

**Levers** (:func:`apply_levers`, :class:`grainfrac_yade.kernel.levers.Levers`), the YADE adapter's draws
from the same random stream in the same order:

* ``strength_cv``: each bond's J^T and J^C x one lognormal factor of mean 1 (YADE: FnMax and FsMax, the same
  strengths times the bond's area);
* ``slit_fraction``: a random share of the bonds broken before loading (:data:`PRE_EXISTING`), one at a time,
  each at zero load (a broken contact: compression and residual friction, no tension);
* ``block_rotation``: every rotation dof fixed at 0 (rigid cells; fem cells' nodes have none: refused).

YADE refuses every lever on fem cells; here ``strength_cv`` and ``slit_fraction`` act on both grain models (they
only change strengths and the broken set), ``block_rotation`` on rigid cells only.
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ...errors import GrainfracError
from ...geometry.disc import DiscTessellation
from ...grains import rotating_grain_models
from ...kernel.levers import PRE_EXISTING, Levers, lever_draws
from .cascade import Path
from .face_failure import failure_for
from .network import StaticNetwork, _side_weights
from .platens import StaticPlatens
from .scene import StaticScene
from .solver import Equilibrium, solver_options

#: Lateral conditions of the jaws (``brazilian.platen_lateral``): "fixed" u_x = 0, "free" u_x free.
LATERALS = ("fixed", "free")
#: The one line that refuses ``block_rotation`` on a grain model without rotation dofs (the grain models whose
#: bodies rotate named as the fix).
BLOCK_ROTATION_REFUSED = ("static engine: --block-rotation blocks the rotation of cells whose bodies rotate; this grain "
                          "model's nodes have no rotation dof; fix: leave it out, or resolution.grain_model = one of "
                          f"{rotating_grain_models()}")


def jaw_cells(tessellation, loading_arc: float) -> tuple:
    """(top, bottom, left, right) cell indices of a disc, by YADE's jaws' rule: top (bottom) the cells whose rim arc
    overlaps ``loading_arc`` [rad] about the top (bottom) end of the vertical diameter, left (right) the cell whose
    rim arc holds the left (right) end of the horizontal diameter, each set without the ones before it.
    GrainfracError (one line) if the specimen is not a disc or a set comes out empty."""
    t = tessellation
    if not isinstance(t, DiscTessellation):
        raise GrainfracError("Brazilian test: the specimen is not a disc; fix: build it with "
                             "grainfrac_yade.geometry.specimen.build_disc_specimen")
    if not (math.isfinite(loading_arc) and 0 <= loading_arc < math.pi):
        raise GrainfracError(f"Brazilian test: loading arc {loading_arc!r} rad must lie in [0, pi); fix: "
                             "brazilian.loading_arc_deg in [0, 180)")
    half = 0.5 * loading_arc
    top = t.cells_in_arc(0.5 * math.pi, half)
    bottom = np.setdiff1d(t.cells_in_arc(-0.5 * math.pi, half), top)
    left = np.setdiff1d(t.cells_in_arc(math.pi, 0.0), np.concatenate([top, bottom]))
    right = np.setdiff1d(t.cells_in_arc(0.0, 0.0), np.concatenate([top, bottom, left]))
    if not (len(bottom) and len(left) and len(right)):
        raise GrainfracError(f"Brazilian test: a disc of {t.n_cells} cells has no separate cells at the two jaws "
                             "and the ends of the horizontal diameter; fix: use a larger disc or smaller grains")
    return top, bottom, left, right


def loaded_arc_deg(tessellation, cells, pole: float) -> float:
    """Angle [deg] that the union of ``cells``' rim arcs spans about ``pole`` [rad] (YADE's jaws' measure)."""
    t = tessellation
    arcs = t.boundary_arc[np.isin(t.boundary_cell, cells)]
    mid = (arcs.mean(axis=1) - pole + math.pi) % (2 * math.pi) - math.pi
    near = np.abs(mid) < 0.5 * math.pi
    arcs = arcs[near] - (arcs.mean(axis=1) - mid)[near, None]
    return float(math.degrees(arcs[:, 1].max() - arcs[:, 0].min()))


def jaw_network(net: StaticNetwork, tessellation, cells: tuple) -> StaticNetwork:
    """``net`` with the jaws as its platens: top/bottom the nodes of the jaw cells, left/right the nodes of the
    horizontal diameter's end cells, width = height = D (so the platen stress x width x thickness is the load and
    the closure / height the diametral strain).  Bonds, rows and stiffness are ``net``'s, shared."""
    top, bottom, left, right = (np.isin(net.node_cell, c) for c in cells)
    d = float(tessellation.diameter)
    return replace(net, top=top, bottom=bottom & ~top, left=left, right=right,
                   side_weight=_side_weights(net.node_pos, net.node_cell, (left, right), d), width=d, height=d)


class JawEquilibrium(Equilibrium):
    """:class:`.solver.Equilibrium` with more prescribed dofs, each held at 0: the jaw nodes' lateral dofs
    (``lateral_fixed``, rough jaws) and every rotation dof (``block_rotation``, the lever).  The platen dofs,
    the closure's direction and everything else as the plain equilibrium."""

    def __init__(self, net: StaticNetwork, lateral_fixed: bool, block_rotation: bool = False, **kwargs):
        super().__init__(net, **kwargs)
        self.lateral_fixed, self.block_rotation = bool(lateral_fixed), bool(block_rotation)
        if self.lateral_fixed:
            self.platen_fixed[net.dofs[net.top | net.bottom, 0]] = True
        if self.block_rotation:
            rot = net.dofs[:, 2]
            self.platen_fixed[rot[rot >= 0]] = True


class StaticJaws(StaticPlatens):
    """The two jaws of a static disc scene (what the Brazilian protocol drives; module doc).  As platens of the
    scene (:class:`.scene.StaticPlatens`): :meth:`.scene.StaticScene.run` moves the closure at their speed."""

    name = "Jaws"

    def __init__(self, scene, loading_arc: float, lateral: str = "fixed"):
        if lateral not in LATERALS:
            raise GrainfracError(f"Brazilian test: platen_lateral = {lateral!r}; fix: one of {', '.join(LATERALS)}")
        t = scene.specimen.tessellation
        cells = jaw_cells(t, loading_arc)
        self.top, self.bottom, self.left, self.right = cells
        self.lateral, self.loading_arc = lateral, float(loading_arc)
        self.diameter, self.centre = float(t.diameter), np.asarray(t.centre, float)
        self.loaded_arc_deg = [loaded_arc_deg(t, self.top, 0.5 * math.pi), loaded_arc_deg(t, self.bottom,
                                                                                             -0.5 * math.pi)]
        self.cells = cells
        self.scene = scene
        self._read_max = 0.0     # the largest load read so far [N] (path_max_load)

    def bind(self):
        """After the scene took the jaws' network: its sizes (D x D) as the platens' reference."""
        super().__init__(self.scene)

    def set_closing_speed(self, speed: float) -> None:
        """The jaws approach each other at ``speed`` [m/s of the load parameter] (half each)."""
        self.set_axial_velocity(speed)

    def diametral_strain(self) -> float:
        """Jaw closure over the diameter (shortening positive) [1]."""
        return self.scene.state.closure / self.diameter

    def horizontal_strain(self) -> float:
        """Change of the horizontal diameter's end-cell distance over D (compression positive) [1]."""
        return self.lateral_strain()

    def load(self) -> float:
        """Mean reaction of the two jaws along the diameter (compression positive) [N]: P = platen stress x D x t.
        Each load read is kept for :meth:`path_max_load`."""
        net = self.scene.net
        p = float(self.scene.state.stress) * net.width * net.thickness
        self._read_max = max(self._read_max, p)
        return p

    def path_max_load(self) -> float:
        """The largest jaw load on the path so far [N]: at a bond's crossing before its cascade (where the path's
        load has its local maxima, :class:`.cascade.Record`), or where the load was read (the history's rows).  The
        protocol's rows sample the path, so their largest load is this one or a little below it."""
        net = self.scene.net
        crossings = [r.stress_before * net.width * net.thickness for r in self.scene.path.records]
        return max([self._read_max, *crossings])

    def summary_keys(self) -> dict:
        """What a run's summary records of the static jaws: the largest load on the path and its 2 P / (pi D t)."""
        p = self.path_max_load()
        t = self.scene.net.thickness
        return {"static_path_max_load_n": p, "static_path_max_tensile_stress_pa": 2 * p / (math.pi * self.diameter * t)}

    def state_dict(self) -> dict:
        return {"velocity": self.velocity, "closure": float(self.scene.state.closure), "load_n": self.load(),
                "lateral": self.lateral, "path_max_load_n": self.path_max_load(),
                "rotation_blocked": bool(getattr(self.scene, "rotation_blocked", False))}

    def restore_state(self, saved: dict) -> None:
        """The platens' restore (:class:`grainfrac_yade.engines.PlatenDrive`) of the jaws: :meth:`rebind`."""
        self.rebind(saved)

    def rebind(self, state) -> None:
        """After a restore: the closing speed, the largest load so far and a blocked rotation (the lever, applied
        before the checkpoint) from ``state`` (:meth:`state_dict`); the closure and the load are the restored
        scene's, which the blocked rotation already holds (no solve)."""
        if not isinstance(state, dict):
            return
        self.velocity = float(state["velocity"])
        self._read_max = float(state.get("path_max_load_n", 0.0))
        scene = self.scene
        if state.get("rotation_blocked") and not getattr(scene, "rotation_blocked", False):
            scene.rotation_blocked = True
            set_equilibrium(scene, jaw_equilibrium(scene, self.lateral == "fixed", True), solve=False)


def jaw_equilibrium(scene, lateral_fixed: bool, block_rotation: bool) -> JawEquilibrium:
    """The scene's :class:`JawEquilibrium` on its network, with the solver options its parameters set
    (:func:`.solver.solver_options`)."""
    return JawEquilibrium(scene.net, lateral_fixed, block_rotation, **solver_options(scene.params))


def attach_jaws(scene, loading_arc: float, lateral: str = "fixed") -> StaticJaws:
    """Put the jaws on a static disc ``scene`` before its loading (module doc): the scene's network takes the jaw
    cells as its platens, its equilibrium the jaws' lateral condition (and a blocked rotation, if the lever asked for
    it), the strengths, broken set and counters are kept, and the state is solved again at zero closure.  The load
    parameter's increment becomes ``brazilian.record_strain_increment / brazilian.strain_rate`` (one history row
    per solved increment).  GrainfracError (one line) on a scene already loaded."""
    if scene.state.closure != 0.0 or scene.hold_target is not None or scene.confinement_stress != 0.0:
        raise GrainfracError("static engine: the jaws go on a disc before it is loaded (no closure, hold or "
                             "confinement yet); fix: attach_jaws right after build_scene and the levers")
    jaws = StaticJaws(scene, loading_arc, lateral)
    scene.net = jaw_network(scene.net, scene.specimen.tessellation, jaws.cells)
    set_equilibrium(scene, jaw_equilibrium(scene, lateral == "fixed", getattr(scene, "rotation_blocked", False)))
    jaws.bind()
    scene.drivers = [d for d in scene.drivers if not isinstance(d, StaticPlatens)] + [jaws]
    bz = scene.params.brazilian
    scene._dt = bz.record_strain_increment / bz.strain_rate
    return jaws


class DiscScene(StaticScene):
    """The static scene of a Brazilian disc: a :class:`.scene.StaticScene` whose ``attach_jaws`` puts the jaws of
    this module on it (:func:`attach_jaws`)."""

    def attach_jaws(self, loading_arc: float, lateral: str = "fixed") -> StaticJaws:
        return attach_jaws(self, loading_arc, lateral)


def set_equilibrium(scene, eq: Equilibrium, solve: bool = True) -> None:
    """``eq`` as ``scene``'s equilibrium: counters, strengths and failure criterion carried over, the state solved again
    where it is (``solve`` False: a restored state that ``eq``'s constraints already hold is kept as it is, and with
    it the solver's kept factor that came back with the checkpoint)."""
    eq.counters = scene.eq.counters
    if not solve:
        eq.restore_factor_state(scene.eq.factor_state())
    jt, jc = scene.path.jt, scene.path.jc
    scene.eq, scene.path = eq, Path(eq)
    scene.path.jt, scene.path.jc, scene.path.failure = jt, jc, failure_for(scene.params, eq.net)
    if solve:
        scene.state = scene.path.cascade(eq.solve(scene.state.closure, scene.state))


def apply_levers(scene, levers: Levers, seed: int) -> dict:
    """Apply ``levers`` to a static ``scene`` before its loading (module doc); what was done (counts), as YADE's
    ``apply_levers`` reports it.  With every lever off nothing is touched."""
    done = {"levers": levers.to_dict()}
    if not levers.active:
        return done
    if scene.state.closure != 0.0 or scene.broken.any():
        raise GrainfracError("levers: the scene has already been loaded; fix: apply levers right after build_scene")
    if levers.block_rotation and not (scene.net.dofs[:, 2] >= 0).any():
        raise GrainfracError(BLOCK_ROTATION_REFUSED)
    factor, slits = lever_draws(levers, seed, scene.n_bonds)
    if factor is not None:
        jt, jc = scene.bond_strengths()
        scene.write_bond_strengths(np.arange(scene.n_bonds), jt * factor, jc * factor)
        done["strength_factor_mean"] = float(factor.mean())
    if slits is not None:
        scene.break_bonds(slits, PRE_EXISTING)
        done["n_slits"] = int(len(slits))
    if levers.block_rotation:
        scene.rotation_blocked = True
        eq = scene.eq
        if isinstance(eq, JawEquilibrium):
            set_equilibrium(scene, jaw_equilibrium(scene, eq.lateral_fixed, True))
        else:
            set_equilibrium(scene, jaw_equilibrium(scene, False, True))
    return done
