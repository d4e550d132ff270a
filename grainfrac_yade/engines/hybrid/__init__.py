"""Hybrid engine: the static engine (:mod:`grainfrac_yade.engines.static`) with YADE's dynamic relaxation where the static
equilibrium gives out or a cascade grows (:mod:`.scene`); :mod:`.engine` is what the engine registry returns for
``numerics.engine = "hybrid"``."""
