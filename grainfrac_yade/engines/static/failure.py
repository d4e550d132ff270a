"""The physical failure rule of a held load (pure).

A specimen under a held platen stress S fails when it cannot hold S: after an event (a bond broken by creep,
and the cascade it sets off at the reached closure) the engine follows the loading path in the platen closure
until the platen stress is S again (:func:`grainfrac_yade.engines.static.cascade.Path.hold`).  It fails when

1. **no equilibrium is ahead**: the path's tangent stiffness (dS/dd at the current contact statuses) is not
   positive and no intact bond can reach its strength along it, so the stress can never climb back to S; or
2. **collapse**: regaining S needs the axial strain to grow by more than ``collapse_strain_increment``
   (``creep.collapse_strain_increment``, the same strain as the YADE runs' collapse criterion: the servo
   closing the platens while the strain grows by more than it).

Both are properties of the piecewise linear equilibrium path, which the active-set solve finds exactly: neither
depends on a solver tolerance or iteration limit (tests/test_static_creep.py runs two solver settings).
A solver that gives up (:class:`~grainfrac_yade.errors.NumericalFailure`) is never a failure of the specimen.
"""
from __future__ import annotations

from dataclasses import dataclass

#: Reasons, as written in a summary.
NO_EQUILIBRIUM = ("no equilibrium at the held load: the path's tangent stiffness is not positive and no intact bond "
                  "can reach its strength")
COLLAPSE = "collapse: regaining the held load needs an axial strain increment above collapse_strain_increment"


@dataclass(frozen=True)
class FailureRule:
    """The rule (module doc); ``collapse_strain_increment`` [1] > 0, or 0 for rule 1 alone."""
    collapse_strain_increment: float

    def __post_init__(self):
        if not self.collapse_strain_increment >= 0:
            raise ValueError(f"collapse_strain_increment must be >= 0 (got {self.collapse_strain_increment!r})")

    def collapsed(self, start_closure: float, closure: float, height: float) -> bool:
        """Rule 2: the closure grew by more than the collapse strain since the event began."""
        limit = self.collapse_strain_increment * height
        return self.collapse_strain_increment > 0 and (closure - start_closure) > limit
