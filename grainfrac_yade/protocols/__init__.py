"""The test protocols' engine-neutral half (pure; no engine imported): what any engine's scene
(:class:`grainfrac_yade.engines.Scene`) is read and driven for, written once for every test.

* :mod:`.cracks`: broken bonds by mode and kind, their face pieces for crack maps, the crack tables;
* :mod:`.loading`: a strain-controlled test's history rows, VTK series, numerical-failure end and result;
* :mod:`.creep_loops`: the event clock's and the paper clock's loops over a held specimen;
* :mod:`.corrosion`: a degradation law's state on the bonds (the pure half of stress corrosion);
* :mod:`.levers`: the Brazilian levers and which breaks they leave out of a test's counts;
* :mod:`.columns`: the names of the step counter and engine time in histories and summaries, and older names.
"""
