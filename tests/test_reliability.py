"""Hard cases: numerical failure as an outcome of its own, one notion of balance in the paper clock,
bounded zero-length intervals, no stale or half-written results, bad input as one line.

The creep loops run here on stand-in scenes (plain Python objects with the methods the loops call),
so their logic is tested exactly and fast; the tests marked ``yade`` inject a NaN into a real scene.
"""
import dataclasses
import itertools
import json
import math
import subprocess
import sys
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from conftest import ROOT, needs_yade
from grainfrac_yade.clocks import EventClock, PaperClock
from grainfrac_yade.errors import GrainfracError, NumericalFailure, ParameterError
from grainfrac_yade.params import load_parameters

B1, B2 = 1e-3, 1e-7   # paper section 4.1
JT, JC = 23e6, 52e6   # K-feldspar/K-feldspar strengths, Table 2
TINY = ["specimen.width=3e-3", "specimen.height=6e-3"]


# ------------------------------------------------------------------ stand-ins for the creep loops
class StandInScene:
    def __init__(self, n):
        self.broken = np.zeros(n, bool)
        self.specimen = SimpleNamespace(thickness=1e-3)
        self.steps = 0

    def run(self, n):
        self.steps += n


class StandInBonds:
    """The corrosion engine's interface (paper Eq. 7 as its law) on fixed stresses; ``breaks``: hand-overs
    break the bond; its degrade only counts creep time."""

    def __init__(self, sigma, tau, tensile, cohesion, breaks=False):
        from grainfrac_yade.law.hillig_charles import HilligCharles
        self.sigma, self.tau = np.asarray(sigma, float), np.asarray(tau, float)
        n = len(self.sigma)
        self.scene = StandInScene(n)
        self.law = HilligCharles(B1, B2)
        self.area0, self.tan_phi = np.full(n, 1e-6), np.full(n, math.tan(math.radians(55)))
        self.state = self.law.initial_state(np.full(n, float(tensile)), np.full(n, float(cohesion)), self.tan_phi)
        self.breaks, self.handed, self.creep_time = breaks, [], 0.0

    tensile = property(lambda self: self.state["tensile_strength"])
    cohesion = property(lambda self: self.state["cohesion"])

    def intact(self):
        return np.flatnonzero(~self.scene.broken)

    def stresses(self, idx):
        from grainfrac_yade.law import Stresses
        return Stresses.of(idx, self.sigma[idx], self.tau[idx])

    def degrade(self, dt, stresses):
        self.creep_time += dt

    def write(self, idx):
        pass

    def hand_over_failures(self, idx, sigma, tau, modes):
        self.handed.append(list(idx))
        if self.breaks:
            self.scene.broken[idx] = True


def loop_params(sc=None, cp=None) -> tuple:
    """The shipped ``[stress_corrosion]`` and ``[creep]`` parameters, with the changes ``sc`` and ``cp``
    (dicts), for the clock loops."""
    p = load_parameters()
    return dataclasses.replace(p.stress_corrosion, **(sc or {})), dataclasses.replace(p.creep, **(cp or {}))


class StandInHolder:
    """The creep run's interface: relative unbalanced forces from ``forces``, relaxation always succeeds;
    no stress servo, no checkpoints."""

    servo = None

    def __init__(self, forces=()):
        self.forces = iter(forces)
        self.failed, self.failure_reason = False, ""
        self.rows, self.relaxations, self.last_relaxation_steps = [], 0, 0

    def unbalanced(self, mean_bond_force):
        rel = next(self.forces)
        return rel * mean_bond_force, rel

    def relax(self, creep_time, safe_point=None, resume=None):
        self.relaxations += 1
        self.last_relaxation_steps = 100
        return True

    def record_now(self, creep_time):
        self.rows.append(creep_time)

    def mark_breaks(self, creep_time):
        pass

    def check_failure(self):
        return self.failed

    def safe_point(self, phase, counters):
        """No checkpoints."""

    def progress(self, msg):
        pass


def _paper_loop(f_u, max_relaxation_steps=20, time_limit=1e5):
    from grainfrac_yade.protocols.creep_loops import paper_clock_loop
    holder = StandInHolder(itertools.repeat(f_u))
    bonds = StandInBonds([1e6, 2e6], [5e6, 5e6], JT, JC)
    clock = PaperClock(1e-5, 1e4, 1e-2)
    sc, cp = loop_params({"creep_time_limit": time_limit, "engine_period": 1, "unbalanced_engine_period": 1,
                          "unbalanced_force_reference": "relative"},
                         {"record_period": 10**9, "max_relaxation_steps": max_relaxation_steps})
    paper_clock_loop(holder, bonds, clock, sc, cp)
    return holder, clock


def test_paper_clock_noise_between_the_old_two_thresholds_is_balanced_not_a_collapse():
    """F_u = 5e-3 lies between the former no-equilibrium tolerance (1e-3) and the clock's threshold
    (1e-2), where the measured noise floor is: the step grows to dt_max AND the state counts as
    balanced, so the run reaches its time limit instead of 'failing' after 20 DEM steps."""
    holder, clock = _paper_loop(5e-3)
    assert not holder.failed, holder.failure_reason
    doublings = math.ceil(math.log2(1e4 / 1e-5))      # steps until dt_max
    assert clock.dt == 1e4 and clock.creep_time >= 1e5 and clock.n_steps > doublings > 20


def test_paper_clock_unbalanced_above_its_threshold_fails_after_the_set_steps():
    holder, clock = _paper_loop(2e-2)
    assert holder.failed
    assert holder.failure_reason == ("no equilibrium at the held load (strain runs away): F_u at or above the paper "
                                     "clock's threshold 0.01 for 21 DEM steps")
    assert clock.n_steps == 21 and clock.creep_time == pytest.approx(21 * 1e-5, rel=1e-12)


def test_paper_clock_loop_with_every_bond_broken_is_a_failure_not_an_infinite_force():
    """No intact bond: the relative F_u (mean resultant / mean bond force) would be inf, which the clock
    reads as a blown-up DEM; the loop ends the run as failed instead."""
    from grainfrac_yade.protocols.creep_loops import paper_clock_loop
    holder = StandInHolder(itertools.repeat(0.0))
    bonds = StandInBonds([1e6], [5e6], JT, JC)
    bonds.scene.broken[:] = True
    clock = PaperClock(1e-5, 1e4, 1e-2)
    paper_clock_loop(holder, bonds, clock, *loop_params(
        {"creep_time_limit": 1e5, "engine_period": 1, "unbalanced_engine_period": 1,
         "unbalanced_force_reference": "relative"}, {"record_period": 10**9, "max_relaxation_steps": 20}))
    assert holder.failed and holder.failure_reason == "every bond broken" and clock.n_steps == 0


def test_paper_clock_loop_on_a_nan_unbalanced_force_raises_numerical_failure():
    with pytest.raises(NumericalFailure, match=r"^unbalanced force is nan \(the DEM blew up\)$"):
        _paper_loop(math.nan)


def _event_loop(bonds, holder=None):
    from grainfrac_yade.protocols.creep_loops import event_clock_loop
    holder = holder or StandInHolder()
    clock = EventClock(0.1)
    n = event_clock_loop(holder, bonds, clock)
    return n, holder, clock


def test_a_numerical_failure_in_the_event_loop_keeps_the_count_of_the_events_before_it():
    """The creep run's ``n_events`` (summary.json) counted 0 when a NumericalFailure ended the event loop: the
    loop's own count was lost with the exception.  Two bonds under different shear stresses fail one after the
    other (two events); the relaxation after the second raises."""
    from grainfrac_yade.protocols.creep import CreepRun

    class FailingAfterTheSecond(StandInHolder):
        def relax(self, creep_time, safe_point=None, resume=None):
            super().relax(creep_time)
            if self.corr.scene.broken.all():   # the relaxation after the second event
                raise NumericalFailure("a stand-in blow-up")
            return True

    holder = FailingAfterTheSecond()
    holder.params, holder.n_events = load_parameters(overrides=["stress_corrosion.creep_time_limit=1e30"]), 0
    holder.corr = StandInBonds([0.0, 0.0], [5e6, 10e6], JT, JC, breaks=True)
    with pytest.raises(NumericalFailure, match="a stand-in blow-up"):
        CreepRun.run_event_clock(holder)
    assert holder.corr.scene.broken.all() and holder.n_events == 2 == holder.clock.n_events


def test_repeated_zero_intervals_that_break_nothing_end_after_a_bounded_number():
    """sigma = 0 with J^T = 0: failed by the law (>=) at dt = 0, but a contact law that breaks only
    on F > FnMax never breaks it; the loop used to hand it over and relax forever."""
    from grainfrac_yade.protocols.creep_loops import MAX_STALLED_INTERVALS
    bonds = StandInBonds([0.0], [0.0], 0.0, JC, breaks=False)
    holder = StandInHolder()
    with pytest.raises(NumericalFailure) as err:
        _event_loop(bonds, holder)
    assert str(err.value) == (f"{MAX_STALLED_INTERVALS} creep intervals of length 0 in a row broke no bond (creep "
                              "time 0 s): a bond at its failure point that the contact law does not break")
    assert len(bonds.handed) == MAX_STALLED_INTERVALS and holder.relaxations == 1 + MAX_STALLED_INTERVALS


def test_zero_intervals_that_break_bonds_are_progress_not_a_stall():
    bonds = StandInBonds([0.0, 0.0], [0.0, 0.0], 0.0, JC, breaks=True)
    n_events, holder, clock = _event_loop(bonds)
    assert n_events == 1 and clock.n_events == 1 and bonds.scene.broken.all() and holder.relaxations == 2


def test_a_run_failing_in_its_first_relaxation_records_that_state():
    """A specimen that fails in the relaxation right after its ramp (fem cells, 10 x 20 mm, seed 3 at
    0.85: a slow cascade that never settles) ends at creep time 0 with a history row of that state, so
    its cracks count; the row was missing and the summary counted only the ramp's cracks."""
    class FailingFirst(StandInHolder):
        def relax(self, creep_time, safe_point=None, resume=None):
            super().relax(creep_time)
            self.failed, self.failure_reason = True, "no equilibrium at the held load (strain runs away)"
            return False
    holder = FailingFirst()
    n_events, holder, clock = _event_loop(StandInBonds([1e6], [0.0], JT, JC), holder)
    assert n_events == 0 and holder.rows == [0.0] and holder.relaxations == 1 and clock.creep_time == 0.0


def test_event_loop_on_nan_stresses_raises_instead_of_ending_not_failed():
    bonds = StandInBonds([1e6, math.nan], [0.0, 0.0], JT, JC)
    holder = StandInHolder()
    with pytest.raises(NumericalFailure, match="^normal_stress is NaN or infinite at 1 of 2 bond"):
        _event_loop(bonds, holder)
    assert holder.rows == [0.0] and not bonds.handed


# ------------------------------------------------------------------ the run folder of a numerical failure
@pytest.fixture(scope="module")
def tiny():
    from grainfrac_yade.grains import layout_for
    from grainfrac_yade.geometry.specimen import build_specimen
    params = load_parameters(overrides=TINY)
    specimen = build_specimen(params, 1)
    return params, specimen, layout_for(specimen, params)


def stand_in_run(tiny, rows, failed=False, numerical=False, reason=""):
    _, specimen, layout = tiny
    n = layout.n_bonds
    broken = np.zeros(n, bool)
    broken[:2] = True
    scene = SimpleNamespace(specimen=specimen, layout=layout, n_bonds=n, broken=broken, break_step=np.full(n, -1),
                            break_mode=np.where(broken, 1, 0), bond_is_inter=np.zeros(n, bool),
                            steps=1234, sliding_erasures=lambda: 0, summary_keys=lambda: {})
    return SimpleNamespace(rows=rows, ramp_broken=2, failed=failed, failure_reason=reason, failed_on_loading=False,
                           failed_before_test=False,
                           numerical_failure=numerical, n_events=0, scene=scene, vtk_written=[],
                           initial_bond_stresses=None, break_time=np.where(broken, -1.0, np.nan),
                           macro_time=np.full(n, np.nan), vtk_folder=None, vtk_times=[], vtk_merged=[])


def history_row(t, strain=2e-3):
    return {"creep_time_s": t, "axial_strain": strain, "lateral_strain": -4e-4, "axial_stress_pa": 2e8,
            "broken_total": 2, "broken_tensile": 2, "broken_shear": 0, "broken_inter": 0, "broken_intra": 2,
            "macrocracks": 0, "step": 1000, "wall_s": 0.1}


def _no_nan(path):
    """JSON without NaN/Infinity tokens (Python's json would accept them)."""
    def refuse(token):
        raise AssertionError(f"{path}: {token}")
    return json.loads(path.read_text(), parse_constant=refuse)


def _creep_folder(tmp_path, monkeypatch, tiny, run):
    from grainfrac_yade.protocols.creep_output import run_creep_to_folder
    from grainfrac_yade.protocols import creep as creep_test
    monkeypatch.setattr(creep_test, "run_creep", lambda specimen, params, stress, progress=None, **outputs: run)
    out = tmp_path / "run"
    run_creep_to_folder(tiny[0], 1, out, 200e6, 0.7, 285e6)
    return out


@pytest.mark.parametrize("rows", [0, 2])
def test_a_numerical_failure_is_its_own_outcome_in_summary_json(tmp_path, monkeypatch, tiny, rows):
    """During the ramp (no history row yet) or in creep: failed null (unknown), no lifetime, the reason,
    numerical_failure true; the history holds only finite rows; nothing NaN in the JSON."""
    reason = "numerical failure: resultant force is NaN or infinite at 3 of 20 body(s) (first: body 5, nan)"
    run = stand_in_run(tiny, [history_row(t) for t in (0.0, 50.0)][:rows], numerical=True, reason=reason)
    out = _creep_folder(tmp_path, monkeypatch, tiny, run)
    s = _no_nan(out / "summary.json")
    assert (s["numerical_failure"], s["failed"], s["lifetime_s"], s["failure_reason"]) == (True, None, None, reason)
    assert s["creep_time_end_s"] == (50.0 if rows else 0.0) and s["broken_total"] == 2
    assert s["primary_end_s"] is None and s["tertiary_start_s"] is None
    if rows:
        hist = pd.read_csv(out / "history.csv")
        assert len(hist) == 2 and np.isfinite(hist.select_dtypes("number").to_numpy()).all()
    else:
        assert not (out / "history.csv").exists()
    from grainfrac_yade.analysis import classify_runs, collect_runs
    assert list(classify_runs(collect_runs(tmp_path))["outcome"]) == ["numerical failure"]
    from grainfrac_yade.commands._outcome import outcome
    assert outcome(s) == f"no result ({reason})"


def test_a_run_killed_while_drawing_leaves_no_summary(tmp_path, monkeypatch, tiny):
    """summary.json is written last: a run stopped before it ends is 'unfinished', never 'finished'."""
    import grainfrac_yade.analysis.plotting as plotting

    def killed(*args, **kwargs):
        raise KeyboardInterrupt
    monkeypatch.setattr(plotting, "crack_map", killed)
    run = stand_in_run(tiny, [history_row(t) for t in (0.0, 10.0, 20.0)], failed=True, reason="strain runs away")
    with pytest.raises(KeyboardInterrupt):
        _creep_folder(tmp_path, monkeypatch, tiny, run)
    out = tmp_path / "run"
    assert (out / "history.csv").exists() and (out / "run.json").exists()
    assert not (out / "summary.json").exists()
    from grainfrac_yade.analysis import classify_runs, collect_runs
    assert list(classify_runs(collect_runs(tmp_path))["outcome"]) == ["unfinished"]


def test_the_analysis_lists_numerical_failures_apart(tmp_path):
    """Never fitted, never a lower bound; listed with the reason in the report and in runs.csv."""
    from test_analysis import true_lifetime, write_run
    from grainfrac_yade.analysis.study import analyze_study, lifetime_sets, load_study
    for r in (0.7, 0.8):
        write_run(tmp_path, f"ratio{r}", r, lifetime=true_lifetime(r))
    d = write_run(tmp_path, "blown_up", 0.75, lifetime=1e6)
    s = json.loads((d / "summary.json").read_text())
    s.update(failed=None, lifetime_s=None, numerical_failure=True, creep_time_end_s=123.0,
             failure_reason="numerical failure: bond normal force is NaN or infinite at 1 of 700 bond(s)")
    (d / "summary.json").write_text(json.dumps(s))
    runs = load_study(tmp_path)
    row = runs.set_index("run").loc["blown_up"]
    assert row["outcome"] == "numerical failure" and row["problem"] == s["failure_reason"]
    (lifetimes,) = lifetime_sets(runs)
    assert sorted(lifetimes.ratio) == [0.7, 0.8] and len(lifetimes.lower_ratio) == 0
    report = analyze_study(tmp_path, grains=False).read_text()
    assert "1 numerical failure(s) (no result: not fitted, not a lower bound)" in report
    table = pd.read_csv(tmp_path / "report" / "runs.csv").set_index("run")
    assert table.loc["blown_up", "outcome"] == "numerical failure"


# ------------------------------------------------------------------ atomic writers, no stale summary
@pytest.mark.parametrize("writer, data", [("write_json", {"new": 2}), ("write_csv", {"new": [2]})])
def test_a_write_killed_before_the_rename_leaves_the_old_file_whole(tmp_path, monkeypatch, writer, data):
    import grainfrac_yade.runs.runio as runio
    target = tmp_path / "file"
    target.write_text("old content\n")

    def killed(src, dst):
        raise KeyboardInterrupt
    monkeypatch.setattr(runio.os, "replace", killed)
    with pytest.raises(KeyboardInterrupt):
        getattr(runio, writer)(target, data)
    assert target.read_text() == "old content\n"
    assert (tmp_path / "file.tmp").exists()


def test_a_replacing_run_is_written_beside_the_old_one_and_swapped_in_when_finished(tmp_path):
    from grainfrac_yade.runs.runio import commit_run_dir, prepare_run_dir, write_json
    params = load_parameters(overrides=TINY)
    out = prepare_run_dir(tmp_path / "r", "creep", params, 1)
    write_json(out / "summary.json", {"failed": True})
    new = prepare_run_dir(out, "creep", params, 1, overwrite=True)
    assert new != out and not (new / "summary.json").exists()
    assert (out / "summary.json").exists()          # the old run is intact until the new one has finished
    assert commit_run_dir(new) == out and not new.exists()
    assert not (out / "summary.json").exists() and (out / "run.json").exists()


# ------------------------------------------------------------------ batch rows: no stale results
VALUES = {"seed": 1, "stress_pa": 2e8}


def finished_folder(path, params, values=VALUES, drop=()):
    from grainfrac_yade.runs.runio import prepare_run_dir, write_json
    out = prepare_run_dir(path, "creep", params, values["seed"])
    stored = json.loads((out / "params.json").read_text())
    for dotted in drop:
        section, key = dotted.split(".")
        del stored[section][key]
    stored["sources"] = ["/elsewhere/params/ldb_granite.toml"]   # provenance: never compared
    (out / "params.json").write_text(json.dumps(stored))
    write_json(out / "summary.json", dict(values, failed=True))
    return out


def test_a_finished_row_is_skipped_only_with_equal_parameters(tmp_path):
    from grainfrac_yade.engines.yade.batch import row_folder
    params = load_parameters(overrides=TINY)
    out = finished_folder(tmp_path / "row", params)
    assert row_folder(out, params, {"on_change": "stop"}, VALUES) == (out, True)
    unfinished = tmp_path / "unfinished"
    unfinished.mkdir()
    assert row_folder(unfinished, params, {"on_change": "stop"}, VALUES) == (unfinished, False)
    edited = load_parameters(overrides=TINY + ["stress_corrosion.beta1=2e-3"])
    with pytest.raises(GrainfracError) as err:
        row_folder(out, edited, {"on_change": "stop"}, dict(VALUES, seed=2))
    assert str(err.value) == (f"{out}: holds a finished run with other parameters (stress_corrosion.beta1: stored "
                              "0.001, now 0.002; seed: stored 1, now 2); fix: give the row another out or study, "
                              "remove the folder, or add a column on_change with 'new_folder' to run it into a new "
                              "folder")


def test_on_change_new_folder_runs_into_a_folder_named_by_the_parameters(tmp_path):
    from grainfrac_yade.runs.runio import run_digest
    from grainfrac_yade.engines.yade.batch import row_folder
    params = load_parameters(overrides=TINY)
    out = finished_folder(tmp_path / "row", params)
    edited = load_parameters(overrides=TINY + ["stress_corrosion.beta1=2e-3"])
    new = tmp_path / f"row_{run_digest(edited, VALUES)}"
    assert new != out and len(new.name) == len("row_") + 8
    assert row_folder(out, edited, {"on_change": "new_folder"}, VALUES) == (new, False)
    finished_folder(new, edited)
    assert row_folder(out, edited, {"on_change": "new_folder"}, VALUES) == (new, True)   # a rerun skips it


def test_a_key_older_params_files_lack_counts_as_its_default(tmp_path):
    from grainfrac_yade.engines.yade.batch import row_folder
    params = load_parameters(overrides=TINY)
    out = finished_folder(tmp_path / "old", params, drop=("resolution.nodes_per_face",))
    assert row_folder(out, params, {"on_change": "stop"}, VALUES) == (out, True)
    three = load_parameters(overrides=TINY + ["resolution.nodes_per_face=3"])
    with pytest.raises(GrainfracError, match=r"\(resolution.nodes_per_face: stored 2, now 3\)"):
        row_folder(out, three, {"on_change": "stop"}, VALUES)


@pytest.mark.parametrize("column, nearest", [("stress_corosion.beta1", "stress_corrosion.beta1"),
                                             ("beta1", "stress_corrosion.beta1"), ("sed", "seed"),
                                             ("on_chnage", "on_change"), ("specimen.widht", "specimen.width")])
def test_a_misspelt_column_names_the_nearest_valid_key(column, nearest):
    from grainfrac_yade.params import shipped_values
    from grainfrac_yade.engines.yade.batch import RUN_COLUMNS, check_columns
    valid = {**shipped_values(), **RUN_COLUMNS, "ratio": 0.0}
    check_columns(["specimen.width", "seed", "description", "!note"], valid, "t.table:2")   # all valid: quiet
    with pytest.raises(GrainfracError) as err:
        check_columns(["seed", column], valid, "t.table:2")
    assert str(err.value) == f"batch table t.table:2: unknown column {column!r}; fix: did you mean {nearest}?"


def test_a_column_like_no_key_lists_what_columns_may_be():
    from grainfrac_yade.engines.yade.batch import RUN_COLUMNS, check_columns
    with pytest.raises(GrainfracError) as err:
        check_columns(["qqqq"], dict(RUN_COLUMNS), "t.table:2")
    assert str(err.value) == ("batch table t.table:2: unknown column 'qqqq'; fix: columns are parameter paths "
                              "(section.key, as in params/*.toml) or seed, out, study, description, on_change")


# ------------------------------------------------------------------ bad input: one line
@pytest.mark.parametrize("grain", ["10e-3", "12e-3"])
def test_a_grain_at_or_above_the_width_is_one_line_naming_key_and_fix(grain):
    with pytest.raises(ParameterError) as err:
        load_parameters(overrides=["specimen.width=10e-3", "specimen.height=20e-3", f"specimen.grain_size={grain}"])
    assert str(err.value) == (f"--set: specimen.grain_size: {float(grain):g} m is at or above the specimen's width "
                              "(0.01 m); fix: make specimen.grain_size smaller than specimen.width (paper: 1 mm in a "
                              "31.7 mm wide specimen) or enlarge the specimen")
    assert load_parameters(overrides=["specimen.width=10e-3", "specimen.grain_size=9.9e-3"])   # one cell wide: fine


def test_misspelt_set_key_names_the_nearest():
    with pytest.raises(ParameterError) as err:
        load_parameters(overrides=["stress_corosion.beta1=2e-3"])
    assert str(err.value) == "--set: stress_corosion.beta1: no such parameter; fix: did you mean stress_corrosion.beta1?"


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "grainfrac_yade", *map(str, args)], capture_output=True, text=True,
                          cwd=ROOT)


def test_cli_grain_above_the_width_exits_2_with_one_line(tmp_path):
    res = _cli("specimen", "--width", "10e-3", "--height", "20e-3", "--grain-size", "12e-3", "--out", tmp_path / "x")
    assert res.returncode == 2 and "Traceback" not in res.stderr
    assert res.stderr.splitlines() == [
        "error: --grain-size: specimen.grain_size: 0.012 m is at or above the specimen's width (0.01 m); fix: make "
        "specimen.grain_size smaller than specimen.width (paper: 1 mm in a 31.7 mm wide specimen) or enlarge the "
        "specimen"]
    assert not (tmp_path / "x").exists()


@pytest.mark.parametrize("command, extra", [("ucs", ()), ("creep", ("--ratio", "0.7")), ("elastic", ()),
                                            ("demo", ())])
def test_a_3d_specimen_is_refused_at_the_start_with_one_line(tmp_path, command, extra):
    res = _cli(command, *extra, "--set", "specimen.dimension=3", "--out", tmp_path / "x")
    assert res.returncode == 2
    assert res.stderr.splitlines() == [
        f"error: specimen.dimension = 3: the {command} command runs plane (2D) specimens only; fix: set "
        "specimen.dimension = 2 (the specimen command builds 3D specimens)"]
    assert not (tmp_path / "x").exists()


def test_the_specimen_command_still_builds_3d(tmp_path):
    res = _cli("specimen", "--set", "specimen.dimension=3", "--width", "3e-3", "--height", "4e-3", "--set",
               "specimen.thickness=3e-3", "--out", tmp_path / "x")
    assert res.returncode == 0, res.stderr
    assert json.loads((tmp_path / "x" / "specimen.json").read_text())["dimension"] == 3


# ------------------------------------------------------------------ in YADE: a real NaN
def _inject_nan(monkeypatch, method, after):
    """Before or ``after`` CreepRun.<method>, give one free body a NaN velocity: the DEM steps spread it."""
    from grainfrac_yade.protocols import creep as creep_protocol
    original = getattr(creep_protocol.CreepRun, method)

    def poison(run):
        from yade import Vector3
        run.scene.O.bodies[run.scene.free_bodies()[0]].state.vel = Vector3(math.nan, math.nan, 0.0)

    def poisoned(self, *args, **kwargs):
        if not after:
            poison(self)
        result = original(self, *args, **kwargs)
        if after:
            poison(self)
        return result
    monkeypatch.setattr(creep_protocol.CreepRun, method, poisoned)


@needs_yade
@pytest.mark.yade
@pytest.mark.parametrize("phase, method, after, reason", [
    ("ramp", "ramp", False, "axial stress during the ramp is nan at DEM step {steps}"),
    ("creep", "hold_servo", True, "bond force is NaN or infinite at {n} of {n} bond(s) (first: bond 0, nan)")])
def test_yade_nan_ends_the_run_as_a_numerical_failure(tmp_path, monkeypatch, phase, method, after, reason):
    """A NaN velocity spreads through the scene: during the ramp (it used to end 'failed on loading' once
    the platen strain passed the cap) or at the first relaxation of the creep phase (it used to end
    'no equilibrium', i.e. a lifetime)."""
    from grainfrac_yade.protocols.creep_output import run_creep_to_folder
    _inject_nan(monkeypatch, method, after)
    params = load_parameters(overrides=TINY)
    s = run_creep_to_folder(params, 1, tmp_path / "run", 0.7 * 300e6, 0.7, 300e6)
    assert s["numerical_failure"] is True and s["failed"] is None and s["lifetime_s"] is None
    assert not s["failed_on_loading"] and s["creep_time_end_s"] == 0.0
    assert s["failure_reason"] == "numerical failure: " + reason.format(n=s["n_bonds"], steps=s["steps"])
    assert _no_nan(tmp_path / "run" / "summary.json")["numerical_failure"] is True
    if phase == "ramp":
        assert not (tmp_path / "run" / "history.csv").exists()
    else:
        hist = pd.read_csv(tmp_path / "run" / "history.csv")
        assert len(hist) == 1 and np.isfinite(hist.select_dtypes("number").to_numpy()).all()


@needs_yade
@pytest.mark.yade
def test_yade_bond_never_gets_a_nan_strength():
    """write() and hand_over_failures() refuse non-finite values before touching YADE (Python's
    max(nan, 0) is nan, which hand_over_failures would have written as FsMax)."""
    from grainfrac_yade.law import MODE_SHEAR
    from single_bond import BondUnderForce
    holder = BondUnderForce(load_parameters(), 1e6, 0.0)
    phys = holder.scene.interactions[0].phys
    before = (phys.FnMax, phys.FsMax)
    holder.corr.state["tensile_strength"][0] = math.nan
    with pytest.raises(NumericalFailure, match="^value written to a YADE bond is NaN or infinite at 1 of 1 bond"):
        holder.corr.write([0])
    with pytest.raises(NumericalFailure, match="^value written to a YADE bond is NaN or infinite at 1 of 1 bond"):
        holder.corr.hand_over_failures([0], [math.nan], [0.0], [MODE_SHEAR])
    assert (phys.FnMax, phys.FsMax) == before and all(map(math.isfinite, before))


@needs_yade
@pytest.mark.yade
@pytest.mark.parametrize("script", ["specimen", "ucs", "creep"])
def test_every_batch_script_reports_a_misspelt_column_in_one_line(tmp_path, script):
    import os
    import shutil
    from grainfrac_yade.runs.batchrun import write_table
    table = write_table(tmp_path / "t.table", [{"specimen.widht": 3e-3, "ratio": 0.7, "seed": 1,
                                                "out": str(tmp_path / "x")}])
    res = subprocess.run([shutil.which("yade"), "-n", "-x", str(ROOT / "yade_scripts" / f"{script}.py")],
                         env=dict(os.environ, YADE_BATCH=f"{table}:2", OMP_NUM_THREADS="1"), capture_output=True,
                         text=True, cwd=ROOT)
    errors = [line for line in res.stdout.splitlines() if line.startswith("error:")]
    assert errors == [f"error: batch table {table}:2: unknown column 'specimen.widht'; fix: did you mean "
                      "specimen.width?"]
    assert res.returncode == 2 and "Traceback" not in res.stdout + res.stderr
    assert not (tmp_path / "x").exists()


class _RampPlatens:
    """Platens whose stress follows a given sequence, one value per ramp check."""

    def __init__(self, stresses, strain_step=1e-5):
        self.stresses, self.strain_step, self.checks = list(stresses), strain_step, 0
        self.height = 20e-3

    def set_axial_velocity(self, speed):
        pass

    def axial_stress(self):
        return self.stresses[min(self.checks, len(self.stresses)) - 1]

    def axial_strain(self):
        return self.checks * self.strain_step


def _ramp(stresses, target):
    from grainfrac_yade.protocols.creep import CreepRun
    run = CreepRun.__new__(CreepRun)
    platens = _RampPlatens(stresses)
    run.platens, run.target = platens, target
    run.params = SimpleNamespace(creep=SimpleNamespace(ramp_strain_rate=0.5, failure_strain=0.02))
    run.scene = SimpleNamespace(dt=1e-7, steps=0, broken=np.zeros(3, dtype=bool),
                                run=lambda n: setattr(platens, "checks", platens.checks + 1))
    run.break_time = np.full(3, np.nan)
    run.failed, run.failed_on_loading, run.failure_reason = False, False, ""
    run.ramp()
    return run


def test_ramp_start_oscillation_is_not_a_failure_on_loading():
    """The measured start of a 6 x 12 mm deformable ramp (MPa per check of 1e-5 strain): 6.76 then
    4.31 is a drop below 0.7 of the peak, but far below the load: the ramp goes on to the target."""
    start = [3.03, 5.87, 6.76, 6.43, 4.31, 5.7, 6.26, 5.86, 6.05, 7.79, 10.8, 11.08]
    run = _ramp([s * 1e6 for s in start] + [50e6, 150e6, 219e6], target=219e6)
    assert not run.failed and run.platens.checks == len(start) + 3


def test_ramp_drop_after_a_real_peak_fails_on_loading():
    """A peak above half the load followed by a drop below 0.7 of it: the load is above the strength."""
    run = _ramp([50e6, 120e6, 150e6, 100e6], target=219e6)
    assert run.failed and run.failed_on_loading and run.platens.checks == 4
    assert run.failure_reason == "failed during the ramp: load above the specimen's strength"
