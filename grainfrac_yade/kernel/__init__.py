"""The kernel that the tests' protocols (:mod:`grainfrac_yade.protocols`) and the engines both import (pure numpy;
it imports neither: no engine module imports a protocol).

* :mod:`.held_relaxation`: the one held-load relaxation loop (DEM steps in chunks of ``creep.check_period`` until
  the load is held at equilibrium, the specimen collapses or the budget is spent), driven through
  :class:`~.held_relaxation.HeldRelaxing`, which each engine implements: a creep hold and the isotropic stage on
  YADE, the static engine's inertial relaxation, the hybrid engine's dynamic stints; the collapse criterion
  (:class:`~.held_relaxation.CollapseWatch`);
* :mod:`.servo`: the stress servo's law (closing speed from the stress error, clipped), behind the engines' servos;
* :mod:`.equilibrium`: the equilibrium criterion of a held load (unbalanced force over the mean bond force, the held
  stress within its tolerance) and the finite-value check of a measure;
* :mod:`.corrosion`: a degradation law's state on the bonds (the pure half of stress corrosion; each engine's bond
  writer is one);
* :mod:`.cracks`: broken bonds by mode and kind, their face pieces for crack maps, the crack tables;
* :mod:`.levers`: the Brazilian levers and which breaks they leave out of a test's counts;
* :mod:`.confinement`: whether a specimen survived a confined test's isotropic stage.
"""
