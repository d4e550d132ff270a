"""What every mechanical engine offers the test protocols: a scene, and its state in an engine-neutral form.

An engine turns a specimen, its parameters and a grain layout (:mod:`grainfrac_yade.grains`) into a
*scene*: bodies (the grain model's nodes) joined by breakable bonds (one per layout bond, Table 2),
loaded by platens.  Two kinds are meant to implement it:

* a dynamic engine (YADE, :mod:`grainfrac_yade.engines.yade`): explicit integration of Newton's law
  with Cundall's non-viscous damping; :meth:`Scene.run` advances DEM steps and
  :meth:`Scene.equilibrate` is dynamic relaxation until the project's equilibrium criterion (mean
  resultant force on the free bodies over the mean bond force, ``creep.equilibrium_tolerance``);
* a quasi-static engine: :meth:`Scene.run` applies load increments, each solved, and
  :meth:`Scene.equilibrate` is one solve.

Engines that integrate motion in time (:attr:`EngineModule.dynamic`) have an unbalanced force
(:meth:`Scene.unbalanced`), which the paper clock (Eq. 8) needs; a creep test's hold is force control by
the platens (:meth:`PlatenDrive.hold_stress`).  Besides the scene, an engine offers the protocols and the
commands an :class:`EngineModule` (its ``engine.py``'s ``ENGINE``): ``build_scene``, ``scene_from_state``,
``consolidate`` (a confined test's isotropic stage), ``apply_levers`` (Brazilian levers) and
``stress_corrosion(scene, sc_params, saved=None)``, the bond writer of a creep test: a
:class:`grainfrac_yade.kernel.corrosion.BondCorrosion` (the degradation law's state, engine-neutral) that
also reads the bond stresses (``stresses``, ``intact``) and writes what the law says they carry (``write``,
``degrade``, ``hand_over_failures``), listed among the scene's engines (``saved``: its state from a
checkpoint); and its checkpoint's scene file, what it refuses and its version.

Counters: :attr:`Scene.steps` counts DEM steps (dynamic) or solves (static); :attr:`Scene.time` is
the engine's own time (DEM time; a static engine's load parameter), both written to the histories
as ``step`` and ``time_s``.  Creep time is separate from both (the clocks of :mod:`grainfrac_yade.clocks`).

Bond quantities follow the layout's bond order (``layout.bond_spheres``): forces in N, tension
positive for the normal force; strengths per intact bond area ``layout.bond_area`` in Pa; break
modes the codes of :mod:`grainfrac_yade.law` (``MODE_TENSION``, ``MODE_SHEAR``).

:class:`SceneState` is the state that one engine exports (:meth:`Scene.export_state`) and another
builds its scene from (its :class:`EngineModule`'s ``scene_from_state``), so that a run can change engine
mid-way, e.g. a quasi-static engine handing a collapse to a dynamic one and taking the result back.
"""
from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Callable, Protocol, runtime_checkable

import numpy as np


@dataclass
class SceneState:
    """The mechanical state of a scene, engine-neutral (numpy arrays; SI units).

    Nodes are the grain model's moving bodies, cell by cell (``node_cell``): one per rigid cell, one
    per sphere of an fem cell.  Positions are in the specimen's frame; displacements from where the
    scene was built; rotations about the out-of-plane axis z [rad].  Velocities are zero for a static
    engine (and read as such by a dynamic one: a relaxed state).

    Bonds follow the layout's bond order.  ``bond_normal_force`` and ``bond_shear_force`` are the
    force vectors the bond's second sphere exerts on its first [N], in the specimen's frame;
    ``bond_reference_gap`` the bond's stress-free normal gap (overlap positive) [m]; ``bond_slip`` the
    path the bond's faces slid [m] (0 where an engine does not track it); ``bond_plane_normal`` the unit
    normal of the plane a bond acts on, for bonds that act on their face's plane (zero otherwise).  Capacities are what the
    bond can carry now [N], in tension and in cohesion (strength x intact area ``layout.bond_area``;
    0 once broken), kept as forces so that a state passes between engines bit for bit.
    ``platens``: the platens' state (reference positions, speed, last reaction), None without platens.
    """
    steps: int
    time: float
    node_cell: np.ndarray
    node_position: np.ndarray
    node_displacement: np.ndarray
    node_velocity: np.ndarray
    node_rotation: np.ndarray
    node_angular_velocity: np.ndarray
    bond_broken: np.ndarray
    bond_mode: np.ndarray
    bond_break_step: np.ndarray
    bond_tensile_capacity: np.ndarray
    bond_cohesive_capacity: np.ndarray
    bond_normal_stiffness: np.ndarray
    bond_shear_stiffness: np.ndarray
    bond_tan_friction: np.ndarray
    bond_normal_force: np.ndarray
    bond_shear_force: np.ndarray
    bond_reference_gap: np.ndarray
    bond_slip: np.ndarray
    bond_plane_normal: np.ndarray
    platens: dict | None = field(default=None)

    def arrays(self) -> dict:
        """The array fields by name (for an ``.npz``)."""
        return {f.name: np.asarray(getattr(self, f.name)) for f in fields(self) if f.name != "platens"}

    @classmethod
    def from_arrays(cls, arrays: dict, platens: dict | None = None) -> "SceneState":
        """The inverse of :meth:`arrays` (``steps`` and ``time`` back as Python numbers)."""
        values = {k: np.asarray(arrays[k]) for k in (f.name for f in fields(cls)) if k != "platens"}
        values["steps"], values["time"] = int(values["steps"]), float(values["time"])
        return cls(**values, platens=platens)

    def differences(self, other: "SceneState") -> list:
        """Names of the fields in which ``other`` differs from this state, bit for bit ([] if none)."""
        out = [name for name, a in self.arrays().items()
               if not np.array_equal(a, other.arrays()[name], equal_nan=a.dtype.kind == "f")]
        return out + (["platens"] if self.platens != other.platens else [])


@runtime_checkable
class PlatenDrive(Protocol):
    """The rigid platens on the top and bottom cells of a specimen (and its side cells' measures)."""
    height: float
    velocity: float

    def set_axial_velocity(self, closing_speed: float) -> None:
        """Displacement control: the platens approach each other at ``closing_speed`` [m/s] (half each)."""

    def shift(self, closing: float) -> None:
        """Move the platens towards each other by ``closing`` [m] in one jump."""

    def axial_strain(self) -> float:
        """Platen closure over the specimen's height (shortening positive) [1]."""

    def lateral_strain(self) -> float:
        """Change of the side cells' distance over the width (compression positive) [1]."""

    def axial_stress(self) -> float:
        """Mean reaction of the two platens over the cross-section (compression positive) [Pa]."""

    def hold_stress(self, target: float, young: float, response_steps: int, max_speed: float) -> object:
        """Force control from here on: a stress servo that moves the platens so as to hold the axial stress
        at ``target`` [Pa], removing an error in about ``response_steps`` steps on a specimen of axial modulus
        ``young`` [Pa], at closing speeds within +-``max_speed`` [m/s].  The servo has ``target``, ``gain``
        [m/Pa], ``max_speed``, ``stress`` (the last measured axial stress [Pa]), ``clipped`` (+1/-1: the last
        command was clipped closing/opening, 0 not) and ``closing_clipped_steps`` (steps in a row clipped
        closing: a collapse the platens cannot hold)."""

    def resume_hold(self, saved: dict) -> object:
        """:meth:`hold_stress` as a checkpoint saved it (``saved``: the servo's attributes by name)."""

    def state_dict(self) -> dict:
        """What a checkpoint keeps of the platens (JSON values by name): the closing speed ``velocity`` [m/s], the
        last reaction ``reaction_pa`` [Pa] and the engine's own reference positions from which the strains are
        measured; also a state's ``platens`` (:meth:`Scene.export_state`)."""

    def restore_state(self, saved: dict) -> None:
        """After the scene's restore from a checkpoint (:meth:`Scene.restore_checkpoint`): the platens as
        :meth:`state_dict` saved them (``saved``), their handles on the restored scene fetched anew."""


@runtime_checkable
class Scene(Protocol):
    """A built scene of one engine: what the test protocols read and drive.

    Attributes every scene has: ``specimen``, ``layout``, ``params``, ``props`` (the bonds' intact properties,
    :func:`grainfrac_yade.layout.bond_properties`), ``n_bonds``, and the per-bond
    bookkeeping ``broken`` (bool), ``break_mode`` (law's mode codes) and ``break_step`` (the
    :attr:`steps` count at the break, -1 if intact).
    """
    specimen: object
    layout: object
    params: object
    broken: np.ndarray
    break_mode: np.ndarray
    break_step: np.ndarray

    # ------------------------------------------------------------------ counters
    @property
    def steps(self) -> int:
        """DEM steps (dynamic engine) or solves (static engine) so far."""

    @property
    def time(self) -> float:
        """The engine's time [s]: DEM time, or a static engine's load parameter."""

    @property
    def dt(self) -> float:
        """The engine's step [s] (a dynamic engine's time step; a static engine's load-parameter increment)."""

    @property
    def n_bonds(self) -> int:
        """Breakable bonds (the layout's)."""

    # ------------------------------------------------------------------ advancing
    def run(self, n_steps: int) -> None:
        """Advance ``n_steps`` steps (DEM steps, or solved load increments); breaks are synced after each."""

    def equilibrate(self, balanced: Callable[[], bool], check_steps: int, max_steps: int) -> int | None:
        """Bring the scene to equilibrium under its current loads: the steps it took, None if
        ``balanced()`` did not hold within ``max_steps`` (dynamic relaxation, checked every
        ``check_steps``; a static engine solves once)."""

    def unbalanced(self, reference: float) -> tuple:
        """(largest resultant force on a body the platens do not drive [N], mean resultant force on those
        bodies / ``reference``, inf if ``reference`` <= 0): how far the scene is from equilibrium after the
        last step (0 for a static engine's solved state); ``reference`` is a mean bond force
        (:func:`grainfrac_yade.kernel.equilibrium.mean_bond_force`).  NumericalFailure if a force is not finite."""

    def relaxation_damping(self, damping: float) -> None:
        """The numerical damping of relaxation from here on (YADE: Cundall's non-viscous damping coefficient);
        an engine that solves for equilibrium ignores it."""

    def lose_load_below(self, ratio: float | None) -> None:
        """The test's post-peak rule under displacement control, given by the protocol: a relaxation the engine runs
        with the platens held (a static engine's where its static path gives out) ends as the specimen's failure
        once the platen stress falls below ``ratio`` x the stress it started from (None: never).  An engine whose
        loading is itself dynamic ignores it (the protocol reads the drop off its rows)."""

    # ------------------------------------------------------------------ bonds
    def bond_forces(self, indices=None) -> tuple:
        """(normal force, tension positive; shear force magnitude) [N] of bonds ``indices`` (all: None)."""

    def bond_stresses(self, indices=None) -> tuple:
        """(normal stress, tension positive; shear stress) [Pa] per intact area of bonds ``indices``."""

    def bond_strengths(self, indices=None) -> tuple:
        """(tensile strength, cohesion) [Pa] per intact area that bonds ``indices`` carry now."""

    def write_bond_strengths(self, indices, tensile, cohesion) -> None:
        """Set what intact bonds ``indices`` can carry: tensile strength and cohesion [Pa] per intact area."""

    def break_bonds(self, indices, mode: int) -> None:
        """Break bonds ``indices`` in ``mode``: no cohesion or tension left, residual friction."""

    def bond_separated(self, indices) -> np.ndarray:
        """(n,) True where a bond's crack is open (its spheres further apart than when it was made)."""

    def sliding_erasures(self) -> int:
        """Bonds that lost their cohesion by the engine's own rule rather than a strength criterion."""

    # ------------------------------------------------------------------ cells, platens, confinement
    def cell_positions(self, cells=None) -> np.ndarray:
        """(n, 3) current positions of cells [m]."""

    def cell_motion(self) -> tuple:
        """((n, 2+) positions [m], (n,) rotations about z [rad]): each cell's rigid motion (a deformable cell's
        least-squares fit), what a picture of the moved cells draws (:mod:`grainfrac_yade.protocols.snapshots`)."""

    def bond_shift(self, positions) -> np.ndarray:
        """(b, 2) displacement [m] drawn for each bond (``positions``: those of :meth:`cell_motion`)."""

    def attach_platens(self, lateral: str) -> PlatenDrive:
        """Rigid platens on the end cells (``lateral``: "free" smooth or "fixed" rough), listed among the
        scene's engines; their speed and forces are driven by the protocol."""

    def attach_jaws(self, loading_arc: float, lateral: str) -> object:
        """The two jaws of a Brazilian disc (the cells whose rim arcs overlap ``loading_arc`` [rad] about the ends
        of the vertical diameter): ``set_closing_speed``, ``load``, ``diametral_strain``, ``horizontal_strain``,
        ``diameter``, ``top``/``bottom`` cells, ``loaded_arc_deg``, ``state_dict``/``rebind``."""

    def confine(self, stress: float) -> object:
        """Force control on the side walls: a lateral confining stress sigma_3 [Pa] held on the side cells."""

    def engine_names(self) -> list:
        """The engines and drivers acting on the scene, by name (what the run records)."""

    def counts(self) -> dict:
        """Sizes of the scene as the engine holds it: ``n_bodies``, ``n_interactions`` (real), ``n_bonds``."""

    def summary_keys(self) -> dict:
        """What a run's summary.json records of the engine beyond the common keys (YADE: nothing; static: its
        name and the dynamic-only settings it did not use)."""

    # ------------------------------------------------------------------ state
    def save(self, path) -> None:
        """Write the engine's whole scene to ``path`` (a checkpoint: resuming from it is exact)."""

    def restore(self, path) -> None:
        """Replace this scene (built from the same specimen and parameters) by the one saved at ``path``."""

    def checkpoint_state(self) -> dict:
        """What a checkpoint keeps of the scene beside :meth:`save`'s file (its size, its break bookkeeping)."""

    def restore_checkpoint(self, where, scene_file, saved: dict, arrays: dict, confinement=None) -> None:
        """:meth:`restore` from a checkpoint (``saved``: :meth:`checkpoint_state`, ``arrays``: the bonds'
        ``broken``, ``break_mode``, ``break_step``), refusing another scene's in one line; ``confinement``:
        side-wall forces set again."""

    def export_state(self, platens: PlatenDrive | None = None) -> SceneState:
        """The scene's state in the engine-neutral form (with ``platens``' state if given)."""


def _no_warnings(overrides, params) -> list:
    """A dynamic engine reads every setting: no warning."""
    return []


def _no_refused_settings(params) -> str:
    return ""


@dataclass(frozen=True)
class EngineModule:
    """What one engine offers the test protocols and the commands: the ``ENGINE`` of its sub-package's
    ``engine.py``, which the registry (:func:`grainfrac_yade.engines.registry.engine`) returns.

    ``name``: the value of ``numerics.engine`` that selects it.  ``dynamic``: it integrates motion in time (inertia,
    an unbalanced force: the paper clock's Eq. 8 needs one).  ``scene_file``: the name of the file a checkpoint
    keeps its scene in (:meth:`Scene.save`, :meth:`Scene.restore_checkpoint`).  ``version()``: the versions of
    what it computes with (what a run records).

    The scene: ``build_scene(specimen, params, layout=None)`` and ``scene_from_state(specimen, params, state,
    layout=None)`` (a :class:`Scene`); the hooks the protocols call on it: ``consolidate(scene, platens, stress,
    params)`` (a confined test's isotropic stage), ``apply_levers(scene, levers, seed)`` (Brazilian levers: what
    was done) and ``stress_corrosion(scene, sc_params, saved=None)`` (a creep test's bond writer, a
    :class:`grainfrac_yade.kernel.corrosion.BondCorrosion` listed among the scene's drivers; ``saved``: its
    state from a checkpoint).

    What the command line refuses before a run folder is made: ``unsupported`` (command -> the one line that
    says so and the fix), ``refused_settings(params)`` (the one line refusing a setting it has no model of, "" if
    none: the saw-tooth softening on the dynamic engines), ``vtk_refused`` (the line refusing a VTK series, "" if it writes them), and
    ``warn_dynamic_only(overrides, params)`` (one warning line per setting given that the engine does not read).
    Engine-specific tools, None where an engine has none: ``timings`` (the module of ``bench``'s timings) and
    ``batch_rows`` (the module that reads a yade-batch row: ``read_table``, ``row_errors``, ``row_plan``,
    ``run_folder_name``).
    """
    name: str
    dynamic: bool
    scene_file: str
    version: Callable[[], str]
    build_scene: Callable[..., Scene]
    scene_from_state: Callable[..., Scene]
    consolidate: Callable
    apply_levers: Callable[..., dict]
    stress_corrosion: Callable
    unsupported: dict = field(default_factory=dict)
    vtk_refused: str = ""
    warn_dynamic_only: Callable[[list, object], list] = _no_warnings
    refused_settings: Callable[[object], str] = _no_refused_settings
    timings: object = None
    batch_rows: object = None

    def refusal(self, command: str, params=None) -> str:
        """The one line that refuses ``command`` (with ``params``, if given) on this engine, "" if it runs it."""
        return self.unsupported.get(command, "") or ("" if params is None else self.refused_settings(params))


__all__ = ["EngineModule", "PlatenDrive", "Scene", "SceneState"]
