"""Quasi-static engine (pure numpy and scipy; never imports YADE).

The same specimen, bonds and laws as the YADE scene, solved by static equilibrium between bond failures instead of
explicit dynamic relaxation (docs/engines.md).  One module per job:

* :mod:`.network`: the contact network of a specimen and its grain layout (rigid or fem cells, from
  :mod:`grainfrac_yade.elastic`'s builders): kinematic and force rows of every bond, the grains' stiffness,
  platens and sides, bond strengths, a canonical (numbering-free) bond order;
* :mod:`.contacts`: the contact law as array functions: intact bonds (linear, tension cut-off, Mohr-Coulomb
  shear, paper Eq. 4-5), broken ones (compression only, residual friction, return mapping), stress-to-strength ratios;
* :mod:`.solver`: equilibrium at a platen closure: the active-set iteration on open/closed and stick/slip
  contacts, SuperLU factors, split steps where statuses cycle, cells cut loose, ground springs of a singular factor;
* :mod:`.factoring`: the kept SuperLU factor of the equilibrium's tangent (plain, grounded or the fast path's
  reference), its pivot and residual checks, saved and rebuilt bit for bit;
* :mod:`.tangent`: the fast linear algebra: the tangent assembled on one cached pattern, a kept factor reused by
  low-rank (Woodbury) updates;
* :mod:`.cascade`: bonds broken one at a time, the most overstressed first; the sequentially linear path in the
  platen closure and the return to a held load;
* :mod:`.face_failure`: the path's failure criterion, each bond's own stress (the default) or each face's resultant
  with the face breaking as a whole (``numerics.static_failure``);
* :mod:`.failure`: the physical failure rule under a held load (no equilibrium ahead, or too much strain to regain);
* :mod:`.paths`: the registry that turns ``numerics.static_relaxation`` into the scene's path;
* :mod:`.strategy`: the scene's relaxation strategy (what it does where the plain solve gives out: the plain one
  here, the hybrid engine's dynamic stints) and the public hooks a strategy uses;
* :mod:`.damped`: the overdamped relaxation where no status set settles (backward Euler, an anchor halved step by
  step);
* :mod:`.inertial`: the inertial relaxation there (explicit small-strain dynamics of the same network under the
  creep protocol's servo and criteria; the default);
* :mod:`.scene`: :class:`~.scene.StaticScene`, the engine's scene of :class:`grainfrac_yade.engines.Scene` (load
  increments, the held platen stress, save and restore with the kept factor, the state export);
* :mod:`.platens`: the platens (displacement control of the closure), the held stress of a creep hold and the
  confinement that the protocols drive;
* :mod:`.jaws`: the Brazilian disc's jaw cells as prescribed displacements, and the Brazilian levers;
* :mod:`.settings`: the engine's name and the dynamic-only settings it does not read;
* :mod:`.bench_timing`: what ``bench --static`` and the study scripts read beside the protocols (the solver's
  counters, the path's breaks, the path alone timed for a number of breaks);
* :mod:`.engine`: what the engine registry returns for ``numerics.engine = "static"``.
"""
