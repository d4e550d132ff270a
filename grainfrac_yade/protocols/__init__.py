"""The test protocols (pure; no engine imported): what any engine's scene (:class:`grainfrac_yade.engines.Scene`) is
read and driven for, written once for every test.  The pieces that the engines share with them are the kernel's
(:mod:`grainfrac_yade.kernel`); no engine imports a module of this package.

* :mod:`.ucs`, :mod:`.brazilian`, :mod:`.creep`: the UCS (and confined), Brazilian and creep tests against
  ``Scene`` alone; :mod:`.creep_checkpoint`: a creep run's own state at a checkpoint;
* :mod:`.ucs_output`, :mod:`.brazilian_output`, :mod:`.creep_output`: each test into a run folder (summary,
  history, crack list, figures, VTK series);
* :mod:`.loading`: a strain-controlled test's history rows, numerical-failure end and result;
* :mod:`.creep_loops`: the event clock's and the paper clock's loops over a held specimen;
* :mod:`.checkpoints`: a test's checkpoint beside the engine's saved scene;
* :mod:`.snapshots`: the VTK series of a run, read through the scene interface;
* :mod:`.timed_creep`: the creep run that times itself for ``bench``.

The names of the step counter and engine time in histories and summaries are in :mod:`grainfrac_yade.runs.columns`.
"""
