"""Open a grainfrac-yade run's VTK series in ParaView with colour maps that fit them.

    pvpython docs/paraview_open_run.py RUN_DIR                      # interactive window
    pvpython docs/paraview_open_run.py RUN_DIR --life               # the life-fraction series
    pvpython docs/paraview_open_run.py RUN_DIR --screenshot a.png   # last time step to a PNG
    pvpython docs/paraview_open_run.py RUN_DIR --movie a.png        # every time step: a_0000.png ...

In the ParaView GUI: View > Python Shell > Run Script, after setting ``RUN_DIR`` in the shell's
environment (``import os; os.environ["RUN_DIR"] = "/path/to/run"``).

Shows RUN_DIR/vtk/cells.pvd coloured by mineral (categorical, the project's mineral colours, named
from the files' ``mineral_names`` field data), and over it the broken bonds of bonds.pvd (``state``
> 0) coloured by state: tensile crack blue, shear crack red.  The time axis is the .pvd timestep:
creep time [s] (UCS, Brazilian: the axial or diametral strain).  Written for ParaView 5.11's
paraview.simple API and not run here (Debian bookworm's python3-paraview conflicts with the
python3-vtk9 the project needs: use a paraview.org binary or another machine); nothing in the
project's tests needs ParaView.
"""
import os
import sys

from paraview import servermanager
from paraview.simple import (ColorBy, GetActiveViewOrCreate, GetAnimationScene, GetColorTransferFunction,
                             PVDReader, Render, ResetCamera, SaveScreenshot, Show, Threshold,
                             UpdatePipeline)

#: Mineral colours of grainfrac_yade/analysis/plotting.py (paper Fig. 2a); others grey.
MINERAL_RGB = {"biotite": (0.23, 0.23, 0.23), "k_feldspar": (0.91, 0.63, 0.48), "quartz": (0.85, 0.85, 0.91),
               "plagioclase": (0.96, 0.93, 0.78)}
#: Bond states 1 (tensile crack) and 2 (shear crack), as grainfrac_yade/analysis/plotting.py draws them.
STATE_RGB = {1: (0.12, 0.47, 0.71), 2: (0.84, 0.15, 0.16)}
CRACK_LINE_WIDTH = 3.0


def field_strings(source, name):
    """String field-data array ``name`` of ``source``'s first dataset (e.g. mineral_names)."""
    data = servermanager.Fetch(source)
    arr = data.GetFieldData().GetAbstractArray(name)
    return [arr.GetValue(k) for k in range(arr.GetNumberOfValues())] if arr is not None else []


def categorical(lut, names_by_code, rgb_by_code):
    """Make ``lut`` categorical: one annotated colour per integer code."""
    lut.InterpretValuesAsCategories = 1
    lut.Annotations = [x for code, name in names_by_code.items() for x in (str(code), name)]
    lut.IndexedColors = [c for code in names_by_code for c in rgb_by_code.get(code, (0.6, 0.6, 0.6))]


def open_run(run_dir, life=False):
    prefix = "life_" if life else ""
    folder = os.path.join(run_dir, "vtk")
    cells_file, bonds_file = (os.path.join(folder, f"{prefix}{kind}.pvd") for kind in ("cells", "bonds"))
    for f in (cells_file, bonds_file):
        if not os.path.isfile(f):
            sys.exit(f"{f}: missing; fix: run with --vtk-times/--vtk-every (--vtk-fractions for --life)")
    view = GetActiveViewOrCreate("RenderView")
    view.InteractionMode = "2D"
    view.OrientationAxesVisibility = 0

    cells = PVDReader(FileName=cells_file)
    UpdatePipeline(proxy=cells)
    cd = Show(cells, view)
    ColorBy(cd, ("CELLS", "mineral"))
    names = field_strings(cells, "mineral_names")
    categorical(GetColorTransferFunction("mineral"), dict(enumerate(names)),
                {k: MINERAL_RGB.get(n, (0.6, 0.6, 0.6)) for k, n in enumerate(names)})
    cd.SetScalarBarVisibility(view, True)

    bonds = PVDReader(FileName=bonds_file)
    cracks = Threshold(Input=bonds)
    cracks.Scalars = ["CELLS", "state"]
    cracks.LowerThreshold, cracks.UpperThreshold = 1, 2   # broken bonds only
    bd = Show(cracks, view)
    ColorBy(bd, ("CELLS", "state"))
    categorical(GetColorTransferFunction("state"), {1: "tensile crack", 2: "shear crack"}, STATE_RGB)
    bd.LineWidth = CRACK_LINE_WIDTH
    bd.SetScalarBarVisibility(view, True)

    scene = GetAnimationScene()
    scene.UpdateAnimationUsingDataTimeSteps()   # the .pvd timesteps: creep time (or strain)
    ResetCamera(view)
    return view, scene


def main(argv):
    args = list(argv)
    life = "--life" in args
    shot = movie = None
    if "--screenshot" in args:
        shot = args[args.index("--screenshot") + 1]
    if "--movie" in args:
        movie = args[args.index("--movie") + 1]
    plain = [a for k, a in enumerate(args) if not a.startswith("--") and (k == 0 or args[k - 1] not in
                                                                          ("--screenshot", "--movie"))]
    run_dir = plain[0] if plain else os.environ.get("RUN_DIR")
    if not run_dir:
        sys.exit("usage: pvpython docs/paraview_open_run.py RUN_DIR [--life] [--screenshot FILE.png] [--movie FILE.png]")
    view, scene = open_run(run_dir, life)
    if shot:
        scene.AnimationTime = scene.EndTime
        SaveScreenshot(shot, view, ImageResolution=[800, 1000])
    elif movie:
        from paraview.simple import SaveAnimation
        SaveAnimation(movie, view, ImageResolution=[800, 1000])
    else:
        Render(view)
        from paraview.simple import Interact
        Interact(view)


if __name__ == "__main__":
    main(sys.argv[1:])
