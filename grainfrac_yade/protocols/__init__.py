"""The test protocols' engine-neutral half (pure; no engine imported): what any engine's scene
(:class:`grainfrac_yade.engines.Scene`) is read for, once for every test.

* :mod:`.cracks`: broken bonds by mode and kind, their face pieces for crack maps, the crack tables.
"""
