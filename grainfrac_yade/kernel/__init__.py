"""The kernel that the tests' protocols and the engines both import (pure numpy; no engine, no test protocol).

* :mod:`.held_relaxation`: the one held-load relaxation loop (DEM steps in chunks of ``creep.check_period`` until
  the load is held at equilibrium, the specimen collapses or the budget is spent), driven through
  :class:`~.held_relaxation.HeldRelaxing`, which each engine implements: a creep hold and the isotropic stage on
  YADE, the static engine's inertial relaxation, the hybrid engine's dynamic stints; the collapse criterion
  (:class:`~.held_relaxation.CollapseWatch`);
* :mod:`.servo`: the stress servo's law (closing speed from the stress error, clipped), behind the engines' servos;
* :mod:`.equilibrium`: the equilibrium criterion of a held load (unbalanced force over the mean bond force, the held
  stress within its tolerance) and the finite-value check of a measure.

Nothing here imports :mod:`grainfrac_yade.protocols` or :mod:`grainfrac_yade.engines`.
"""
