"""Levers of a grain-based model on its tensile strength: what they are and which breaks they leave out of
a test's crack counts (engine-neutral; an engine applies them to its scene before the first step,
:func:`grainfrac_yade.engines.yade.levers.apply_levers` for YADE, whose docstring says what each does)."""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from ..errors import GrainfracError

#: Break mode of a bond broken before loading (a slit); 1 = tension and 2 = shear are JCFpm's, 3 the
#: corrosion law's "corroded".
PRE_EXISTING = 4
#: Second word of the random stream of the levers (the first is the specimen's seed).
LEVER_STREAM = 20261127


@dataclass(frozen=True)
class Levers:
    slit_fraction: float = 0.0      # 1, share of bonds broken before loading
    strength_cv: float = 0.0        # 1, coefficient of variation of a per-bond strength factor (lognormal, mean 1)
    block_rotation: bool = False    # cells do not rotate

    def __post_init__(self):
        if not (math.isfinite(self.slit_fraction) and 0 <= self.slit_fraction < 1):
            raise GrainfracError(f"--slit-fraction {self.slit_fraction!r}: must lie in [0, 1); fix: give the share of "
                                 "faces unbonded before loading, e.g. 0.3")
        if not (math.isfinite(self.strength_cv) and self.strength_cv >= 0):
            raise GrainfracError(f"--strength-cv {self.strength_cv!r}: must be >= 0; fix: give a coefficient of "
                                 "variation, e.g. 0.5")

    @property
    def active(self) -> bool:
        return self.slit_fraction > 0 or self.strength_cv > 0 or self.block_rotation

    def to_dict(self) -> dict:
        return asdict(self)


def lever_draws(levers: Levers, seed: int, n_bonds: int) -> tuple:
    """The levers' random draws for ``n_bonds`` bonds, from the stream (``seed``, :data:`LEVER_STREAM`) in the order
    every engine takes them: (per-bond strength factors, lognormal of mean 1 and coefficient of variation
    ``strength_cv``, or None; the sorted bonds to slit, ``slit_fraction`` of them, or None)."""
    rng = np.random.default_rng([int(seed), LEVER_STREAM])
    factor = slits = None
    if levers.strength_cv > 0:
        s2 = math.log1p(levers.strength_cv ** 2)
        factor = rng.lognormal(-0.5 * s2, math.sqrt(s2), n_bonds)
    if levers.slit_fraction > 0:
        slits = np.sort(rng.choice(n_bonds, int(round(levers.slit_fraction * n_bonds)), replace=False))
    return factor, slits


def new_breaks(scene) -> np.ndarray:
    """(n_bonds,) True for bonds broken during the test (tension or shear), not slits."""
    return scene.broken & (scene.break_mode != PRE_EXISTING)
