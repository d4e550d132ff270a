"""The mesh-resolution creep table is written from each UCS run's own UCS (no YADE)."""
import json

from grainfrac_yade.params import load_parameters


def _ucs_run(root, name, width, nodes_per_face, seed, ucs_pa):
    p = load_parameters(overrides=[("specimen.width", width), ("specimen.height", 2 * width),
                                   ("resolution.grain_model", "fem"),
                                   ("resolution.nodes_per_face", nodes_per_face)])
    folder = root / name
    folder.mkdir(parents=True)
    (folder / "summary.json").write_text(json.dumps({"ucs_pa": ucs_pa, "seed": seed, "params": p.to_dict()}))


def test_rows_sit_at_each_runs_own_ucs_and_pass_the_batch_check(tmp_path):
    from grainfrac_yade.commands.batch import check_table
    from studies import fem_size_mesh as study
    runs = tmp_path / "ucs"
    _ucs_run(runs, "a", 10e-3, 2, 1, 280e6)
    _ucs_run(runs, "b", 10e-3, 3, 1, 300e6)
    _ucs_run(runs, "c", 20e-3, 2, 1, 250e6)   # another size: left out
    table = tmp_path / "mesh.table"
    assert study.main([str(runs), "--out", str(table), "--ratios", "0.7,0.85"]) == 0
    test, rows = check_table(table)
    assert test == "creep" and len(rows) == 4
    got = sorted((load_parameters(overrides=o).resolution.nodes_per_face, c["ratio"], c["ucs"])
                 for o, c in rows.values())
    assert got == [(2, 0.7, 280e6), (2, 0.85, 280e6), (3, 0.7, 300e6), (3, 0.85, 300e6)]
    assert all(dict(o)["creep.servo_response_crossings"] == 2 for o, _ in rows.values())


def test_no_ucs_run_of_the_width_is_one_line(tmp_path, capsys):
    from studies import fem_size_mesh as study
    (tmp_path / "ucs").mkdir()
    assert study.main([str(tmp_path / "ucs"), "--out", str(tmp_path / "t.table")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "no finished UCS run" in err and "fix:" in err
    assert not (tmp_path / "t.table").exists()
