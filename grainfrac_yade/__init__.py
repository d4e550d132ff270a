"""grainfrac-yade: grain-based DEM of time-dependent fracture of brittle rock on YADE.

The pure core (parameters, tessellation, minerals, degradation laws and the creep
step (:mod:`grainfrac_yade.law`), creep clocks, analysis) imports no YADE; :mod:`grainfrac_yade.engines.yade` owns YADE.
"""
__version__ = "0.1.0"
