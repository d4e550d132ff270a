"""The test protocols' engine-neutral half (pure; no engine imported): what any engine's scene
(:class:`grainfrac_yade.engines.Scene`) is read and driven for, written once for every test.

* :mod:`.ucs`, :mod:`.brazilian`, :mod:`.creep`: the UCS (and confined), Brazilian and creep tests against
  ``Scene`` alone; :mod:`.confinement`: whether a specimen survived a confined test's isotropic stage;
* :mod:`.ucs_output`, :mod:`.brazilian_output`, :mod:`.creep_output`: each test into a run folder (summary,
  history, crack list, figures, VTK series);
* :mod:`.loading`: a strain-controlled test's history rows, numerical-failure end and result; the equilibrium
  criterion of a held load;
* :mod:`.creep_loops`: the event clock's and the paper clock's loops over a held specimen;
* :mod:`.corrosion`: a degradation law's state on the bonds (the pure half of stress corrosion);
* :mod:`.cracks`: broken bonds by mode and kind, their face pieces for crack maps, the crack tables;
* :mod:`.levers`: the Brazilian levers and which breaks they leave out of a test's counts;
* :mod:`.checkpoints`: a test's checkpoint beside the engine's saved scene;
* :mod:`.snapshots`: the VTK series of a run, read through the scene interface;
* :mod:`.timed_creep`: the creep run that times itself for ``bench``.

The names of the step counter and engine time in histories and summaries are in :mod:`grainfrac_yade.runs.columns`.
"""
