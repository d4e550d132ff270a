"""Intact bonds on face planes against YADE's smooth-joint sliding rule (engines/yade/joints.py).

One bond of a tiny finite-element scene is sheared back and forth, elastically (a quarter of its
cohesion), with every body held by its velocity: its faces' sliding path grows by four amplitudes a
cycle while the net slip stays within one amplitude.  YADE's law zeroes a smooth joint once that path
exceeds twice its smaller sphere's radius; the guard keeps the intact bond, whose shear force then
is the closed form of an elastic joint, k_s x slip.
"""
from pathlib import Path

import numpy as np
import pytest

from conftest import needs_yade
from grainfrac_yade.params import load_parameters
from grainfrac_yade.geometry.specimen import build_specimen

FEM_PRESET = Path(__file__).resolve().parents[1] / "params" / "presets" / "fem_coarse.toml"
TINY = ["specimen.width=3e-3", "specimen.height=6e-3"]
#: DEM steps per quarter cycle of the imposed shear.
QUARTER = 20
#: Shear amplitude as a fraction of the elastic slip at the bond's cohesion (FsMax / k_s).
AMPLITUDE_FRACTION = 0.25


def _sheared_bond(keep: bool):
    """Build the scene, shear its bond of the smallest spheres until its path is 3 x YADE's limit;
    (scene, bond, phys, amplitude [m], slip direction)."""
    from grainfrac_yade.engines.yade.scene import build_scene
    p = load_parameters(extra_files=[FEM_PRESET], overrides=[*TINY, f"numerics.keep_intact_joints={str(keep).lower()}"])
    sc = build_scene(build_specimen(p, 1), p)
    lay = sc.layout
    limit = 2 * lay.sphere_radius[lay.bond_spheres].min(axis=1)
    k = int(np.argmin(limit))
    phys = sc.interactions[k].phys
    amplitude = AMPLITUDE_FRACTION * phys.FsMax / phys.ks
    a, b = (sc.O.bodies[int(sc.sphere_body[s])] for s in lay.bond_spheres[k])
    for body in sc.O.bodies:                      # every body held where it is; only b moves
        body.state.blockedDOFs = "xyzXYZ"
        body.state.vel = body.state.angVel = (0, 0, 0)
    n = lay.bond_normal[k]
    direction = np.array([-n[1], n[0], 0.0])
    speed = amplitude / (QUARTER * sc.O.dt)
    cycles = int(np.ceil(3 * limit[k] / (4 * amplitude)))
    for _ in range(cycles):
        for sign, quarters in ((1, 1), (-1, 2), (1, 1)):
            b.state.vel = tuple(sign * speed * direction)
            sc.run(quarters * QUARTER)
    b.state.vel = tuple(speed * direction)
    sc.run(QUARTER)                               # to the amplitude: slip = amplitude
    return sc, k, phys, amplitude, cycles, limit[k]


@needs_yade
def test_an_intact_bond_outlives_a_sliding_path_of_three_times_yades_limit():
    sc, k, phys, amplitude, cycles, limit = _sheared_bond(keep=True)
    assert 4 * amplitude * cycles > 3 * limit             # the path the bond's faces slid
    assert phys.isCohesive and not sc.broken[k]
    assert sc.sliding_erasures() == 0
    # elastic joint: |F_s| = k_s x slip (the law's incremental sum of k_s x v dt, exact to rounding)
    assert phys.shearForce.norm() == pytest.approx(phys.ks * amplitude, rel=1e-9)


@needs_yade
def test_without_the_guard_yade_erases_the_intact_bond_and_the_scene_counts_it():
    sc, k, phys, amplitude, cycles, limit = _sheared_bond(keep=False)
    # sheared to a quarter of its cohesion only: the law counted no crack, yet the bond is gone
    assert sc.law.nbTensCracks + sc.law.nbShearCracks == 0
    assert not phys.isCohesive and phys.FsMax == 0 and phys.shearForce.norm() == 0
    # the moved sphere's other bond slid as far: every bond without cohesion is counted as erased
    lost = [j for j, inter in enumerate(sc.interactions) if not inter.phys.isCohesive]
    assert k in lost and sc.sliding_erasures() == len(lost)


@needs_yade
def test_the_guard_is_in_fem_scenes_only():
    from grainfrac_yade.engines.yade.scene import build_scene
    fem = load_parameters(extra_files=[FEM_PRESET], overrides=TINY)
    rigid = load_parameters(overrides=TINY)
    assert "IntactJointGuard" in build_scene(build_specimen(fem, 1), fem).engine_names()
    assert "IntactJointGuard" not in build_scene(build_specimen(rigid, 1), rigid).engine_names()


@needs_yade
def test_a_checkpoint_keeps_the_erasure_count():
    """The synced count is scene state: a resumed run reports what the uninterrupted one would."""
    import time
    from types import SimpleNamespace
    from grainfrac_yade.protocols.checkpoints import base_state
    sc, *_ = _sheared_bond(keep=False)
    sc.erased_by_sliding = 3
    run = SimpleNamespace(scene=sc, t0=time.time(), c0=time.process_time())
    assert base_state("ucs", run, "loading", {}, {}, "")["scene"]["erased_by_sliding"] == 3
