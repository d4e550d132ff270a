"""The static path of each ``numerics.static_relaxation``: what a held-load regain does where the static statuses do
not settle (one registry, read once by the static scene).

* ``"none"``: nothing; the engine gives out there (:class:`.cascade.Path`);
* ``"overdamped"``: implicit overdamped relaxation to rest or to the failure rule (:mod:`.damped`);
* ``"inertial"``: explicit dynamics of the same network under the creep protocol's servo and criteria
  (:mod:`.inertial`).
"""
from __future__ import annotations

from .cascade import Path
from .face_failure import failure_for
from . import damped
from .inertial import InertialPath, InertialRelaxation
from .solver import Equilibrium, solver_options
from .teeth import teeth_for

#: (equilibrium, parameters, lateral traction [Pa], masses: () -> (ndof,) array) -> path, per value of
#: ``numerics.static_relaxation``.
PATHS = {
    "none": lambda eq, params, confinement, masses: Path(eq),
    "overdamped": lambda eq, params, confinement, masses: damped.RelaxingPath(
        eq, damped.AnchoredEquilibrium(eq.net, confinement=confinement, **solver_options(params)),
        damped.REST_TOLERANCE, max_steps=params.numerics.static_relaxation_steps),
    "inertial": lambda eq, params, confinement, masses: InertialPath(eq, InertialRelaxation(eq, masses(), params)),
}


def path_for(eq: Equilibrium, params, confinement: float = 0.0, masses=None, relaxation: str | None = None,
             teeth=None) -> Path:
    """The static path on ``eq`` for ``params`` (``numerics.static_relaxation`` picks it from :data:`PATHS`, or
    ``relaxation`` where a scene relaxes its own way) under the lateral traction ``confinement`` [Pa]; ``masses``: a
    callable giving the network's (ndof,) masses (:func:`.inertial.dof_masses`), called only by a path that moves
    with inertia.  The path's saw-tooth softening (:func:`.teeth.teeth_for`; ``teeth``: a former path's, kept) tells
    its equilibria when a bond's stiffness changes; its failure criterion (:func:`.face_failure.failure_for`, each bond's
    own or each face's) is the one its relaxation's dynamics check too."""
    path = PATHS[relaxation or params.numerics.static_relaxation](eq, params, confinement, masses)
    path.teeth = teeth_for(params, eq.net, teeth)
    path.failure = failure_for(params, eq.net)
    if hasattr(path, "dynamics"):
        path.dynamics.failure = path.failure
    if path.teeth is not None:
        path.teeth.equilibria += [e for e in (eq, getattr(path, "anchored", None)) if e is not None]
        if hasattr(path, "dynamics"):
            path.dynamics.teeth = path.teeth
    return path
