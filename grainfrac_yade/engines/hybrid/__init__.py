"""Hybrid engine: the static engine (:mod:`grainfrac_yade.engines.static`) with the relaxation strategy of YADE's
dynamic stints where the static equilibrium gives out or a cascade grows (:mod:`.stints`); :mod:`.engine` composes
the two and is what the engine registry returns for ``numerics.engine = "hybrid"``."""
