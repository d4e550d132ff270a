"""grainfrac-yade: grain-based DEM of time-dependent fracture of brittle rock on YADE.

The pure core (parameters, tessellation, minerals, stress-corrosion law, creep
clocks, analysis) imports no YADE; :mod:`grainfrac_yade.yade_adapter` owns YADE.
"""
__version__ = "0.1.0"
