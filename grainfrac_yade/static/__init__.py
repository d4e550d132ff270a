"""Quasi-static engine, numerical core (pure numpy and scipy; no YADE).

The same specimen, bonds and laws as the YADE scene, solved by static equilibrium between bond failures
instead of explicit dynamic relaxation.  One module per job:

* :mod:`.network`: the contact network of a specimen and its grain layout (rigid or fem cells, from
  :mod:`grainfrac_yade.elastic`'s builders): kinematic and force rows of every bond, the grains' stiffness,
  platens and sides, bond strengths, a canonical (numbering-free) bond order;
* :mod:`.contacts`: the contact law as array functions: intact bonds (linear, tension cut-off, Mohr-Coulomb
  shear), broken ones (compression only, residual friction, return mapping), stress-to-strength ratios;
* :mod:`.solver`: equilibrium at a platen closure: tangent assembly, SuperLU factor (kept while the tangent
  does not change), the active-set iteration on open/closed and stick/slip contacts, cells cut loose;
* :mod:`.cascade`: bonds broken one at a time, the most overstressed first; the sequentially linear path in
  the platen closure (UCS without a loading rate) and the return to a held load (creep holds);
* :mod:`.failure`: the physical failure rule under a held load;
* :mod:`.creep`: the creep hold: the law package's :func:`~grainfrac_yade.law.creep_step` and the event
  clock fed by the static stresses.
"""
