"""Degradation laws of bonded contacts under stress corrosion (pure numpy; no YADE).

One module per law, selected by ``stress_corrosion.law``:

* :mod:`.hillig_charles` (``"hillig_charles"``, the default): paper Eq. 7 on strength,
  dJ/dt = -beta1 exp(beta2 s), with an optional activation threshold (Potyondy 2007);
* :mod:`.normalised` (``"normalised"``): the exponent on stress / strength, dY/dt =
  -beta1 exp(beta2 s/Y) (Potyondy 2007's form), with the same optional threshold;
* :mod:`.area` (``"area"``): corrosion shrinks the bond area, stiffness and capacity with it.

Every law implements :class:`DegradationLaw` (rate; degrade over an interval at frozen stress; time
to failure; failure point and mode) and is built once from the parameters by :func:`build_law`.
:func:`creep_step` is one event of the event clock.  Adding a law: a new module here with a
``NAME`` and a ``build(stress_corrosion_params)``, and its name among the choices of
``stress_corrosion.law`` (:data:`LAW_NAMES`).

The path of beta1 from ``params/stress_corrosion.toml`` to a bond's strength in YADE (6 calls):

1. :func:`grainfrac_yade.params.load_parameters` reads and checks it: ``params.stress_corrosion.beta1``;
2. :func:`build_law` (called once by the adapter's ``StressCorrosion``) gives it to the law:
   ``HilligCharles(beta1, beta2, ...)`` keeps it as ``law.beta1``;
3. :func:`creep_step` (event clock; the paper clock calls :func:`degrade_step`) asks the law for the
   interval and the new state;
4. ``law.step`` / ``law.degrade`` calls
5. :func:`.hillig_charles.degrade` with ``law.beta1``: J <- J - beta1 exp(beta2 s) dt (paper Eq. 7);
6. ``StressCorrosion.write`` puts J A0 into the bond's ``FnMax`` / ``FsMax``.
"""
from __future__ import annotations

import importlib

from ._common import MODE_CORRODED, MODE_NEVER, MODE_SHEAR, MODE_TENSION, check_finite, failed_now, shear_strength
from ._creep_step import CreepStep, creep_step, degrade_step
from ._interface import EVENT_REL_TOL, BondState, DegradationLaw, Stresses

#: Values of ``stress_corrosion.law``: each is the name of a module of this package.
LAW_NAMES = ("hillig_charles", "normalised", "area")


def law_module(name: str):
    """The module of law ``name`` (ValueError naming the choices if there is none)."""
    if name not in LAW_NAMES:
        raise ValueError(f"no degradation law {name!r}; choose one of {', '.join(LAW_NAMES)}")
    return importlib.import_module(f"{__name__}.{name}")


def scales_with_beta1(name) -> bool:
    """Whether every time the law ``name`` gives is exactly proportional to 1/beta1: the law's own
    ``time_scales_with_beta1`` flag (:class:`DegradationLaw`); False for a name that is no law (an
    older run's, say)."""
    return name in LAW_NAMES and law_module(name).LAW.time_scales_with_beta1


def time_scaling_laws() -> tuple:
    """The laws whose times all scale with 1/beta1, in :data:`LAW_NAMES` order."""
    return tuple(n for n in LAW_NAMES if scales_with_beta1(n))


def build_law(sc) -> DegradationLaw:
    """The law ``sc.law`` built once from the ``[stress_corrosion]`` parameters ``sc``."""
    return law_module(sc.law).build(sc)


__all__ = ["LAW_NAMES", "BondState", "CreepStep", "DegradationLaw", "EVENT_REL_TOL", "MODE_CORRODED", "MODE_NEVER",
           "MODE_SHEAR", "MODE_TENSION", "Stresses", "build_law", "check_finite", "creep_step", "degrade_step",
           "failed_now", "law_module", "scales_with_beta1", "shear_strength", "time_scaling_laws"]
