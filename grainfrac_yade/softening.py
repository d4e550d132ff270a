"""Saw-tooth softening of a bond: the sequentially linear approximation of a linear softening envelope (pure numpy).

**Envelope** (Hillerborg, Modeer & Petersson 1976, the fictitious crack with a linear softening law; Bazant & Oh
1983, the crack band): a bond of initial stiffness k_0 and strength f_0 opens elastically to f_0 at the separation
delta_0 = f_0 / k_0, then softens linearly to no force at the ultimate separation mu delta_0 (mu >= 1, the
ductility):

    f(delta) = f_0 (mu delta_0 - delta) / ((mu - 1) delta_0),     delta_0 <= delta <= mu delta_0.

The energy a bond takes to complete separation along it is the triangle under it, G = f_0 delta_0 mu / 2
(:func:`envelope_energy`); mu = 1 is the brittle bond (G = f_0 delta_0 / 2, all of it elastic).

**Saw-tooth** (sequentially linear analysis: Rots, Invernizzi & Belletti 2006, "Saw-tooth softening/stiffening -
a stable computational procedure for RC structures", Computers & Concrete 3; Rots, Belletti & Invernizzi 2008,
"Robust modeling of RC structures with an event-by-event strategy", Eng. Fract. Mech. 75): the envelope replaced
by N linear-elastic teeth i = 0 .. N-1, each a secant stiffness k_i and a strength f_i, with equal strength steps
and each tooth's peak (f_i / k_i, f_i) on the envelope (no ripple band: Rots et al.'s p = 0):

    f_i / f_0 = 1 - i / N,     delta_i / delta_0 = 1 + (mu - 1) i / N,     k_i / k_0 = (f_i / f_0) / (delta_i / delta_0)

(:func:`sawtooth_teeth`).  Tooth 0 is the intact bond; a bond that reaches the strength of tooth i < N - 1 goes on
with tooth i + 1 (its stiffness and strength lowered, the force dropping at fixed separation); at the last tooth it
breaks.  N = 1 or mu = 1 is the brittle bond.

**Energy** of a monotonic opening through all teeth (:func:`sawtooth_energy`): at the peak of tooth i the force
drops at fixed separation delta_i from f_i to k_{i+1} delta_i, releasing the triangle between the two secants,
delta_i (f_i - k_{i+1} delta_i) / 2 (k_N = 0: the last drop releases all that tooth stored).  The teeth lie under
the envelope, and it exceeds them by (:func:`sawtooth_energy_deficit`)

    G - W_N = (mu - 1) f_0 delta_0 / (2 N) + ((mu - 1) delta_0 / N)^2 / 2 sum_{i=1}^{N-1} k_i,

a triangle of height f_0 / N and one of height k_i Delta between each tooth's rising branch and the envelope over
each separation step Delta = (mu - 1) delta_0 / N, so that W_N -> G as N grows, G - W_N ~ G ln(mu) / N.
"""
from __future__ import annotations

import numpy as np


#: The softening choices of ``numerics.static_softening`` (the schema's), with none = the brittle bond.
SOFTENING_NONE, SOFTENING_SAWTOOTH = "none", "sawtooth"


def _check(teeth: int, ductility: float) -> None:
    if int(teeth) != teeth or teeth < 1 or not ductility >= 1.0 or not np.isfinite(ductility):
        raise ValueError(f"saw-tooth: teeth must be an integer >= 1 and the ductility a finite number >= 1 "
                         f"(got {teeth!r}, {ductility!r})")


def sawtooth_teeth(teeth: int, ductility: float) -> tuple:
    """(k_i / k_0, f_i / f_0) per tooth i = 0 .. N-1 (arrays of length N = ``teeth``) of the saw-tooth that
    approximates the linear softening envelope of ductility mu = ``ductility`` (module doc: equal strength steps,
    each peak on the envelope)."""
    _check(teeth, ductility)
    x = np.arange(int(teeth)) / int(teeth)
    strength = 1.0 - x
    separation = 1.0 + (float(ductility) - 1.0) * x
    return strength / separation, strength


def envelope_energy(ductility: float, strength: float = 1.0, separation: float = 1.0) -> float:
    """G = f_0 delta_0 mu / 2: the area under the linear softening envelope (``strength`` f_0, ``separation``
    delta_0 at the peak)."""
    return 0.5 * strength * separation * float(ductility)


def sawtooth_energy(teeth: int, ductility: float, strength: float = 1.0, separation: float = 1.0) -> float:
    """W_N: the energy a monotonic opening through all teeth dissipates, the sum of the triangles between successive
    secants, delta_i (f_i - k_{i+1} delta_i) / 2 with k_N = 0 (module doc)."""
    k, f = sawtooth_teeth(teeth, ductility)
    k0 = strength / separation
    f_i, k_i = f * strength, k * k0
    delta = f_i / k_i
    k_next = np.append(k_i[1:], 0.0)
    return float(np.sum(0.5 * delta * (f_i - k_next * delta)))


def sawtooth_energy_deficit(teeth: int, ductility: float, strength: float = 1.0, separation: float = 1.0) -> float:
    """G - W_N in closed form (module doc): what the teeth leave out of the envelope's area."""
    k, _ = sawtooth_teeth(teeth, ductility)
    step = (float(ductility) - 1.0) * separation / int(teeth)
    k0 = strength / separation
    return 0.5 * step * strength + 0.5 * step ** 2 * k0 * float(np.sum(k[1:]))


def softening_of(numerics) -> tuple | None:
    """(k_i / k_0, f_i / f_0) of the run's teeth (``numerics.static_softening`` and its teeth and ductility), or None
    for the brittle bond: softening "none", one tooth, or a ductility of 1 (every tooth's peak at delta_0)."""
    if numerics.static_softening == SOFTENING_NONE:
        return None
    n, mu = numerics.static_softening_teeth, numerics.static_softening_ductility
    if n == 1 or mu == 1.0:
        return None
    return sawtooth_teeth(n, mu)


def engine_refusal(params, engine: str) -> str:
    """The one line that refuses softening on an engine other than the static one ("" where there is none to
    refuse): the teeth are events of the static engine's sequentially linear path."""
    if params.numerics.static_softening == SOFTENING_NONE:
        return ""
    return (f"numerics.static_softening = {params.numerics.static_softening!r}: the saw-tooth teeth are events of the "
            f"static engine's path, the {engine} engine has none; fix: --engine static, or numerics.static_softening "
            "= \"none\"")

