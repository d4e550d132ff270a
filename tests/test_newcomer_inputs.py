"""Bad input a new user still met after the first round (a binary parameter file, a file value hidden by a flag,
an empty --out, a seed beyond 32 bits, a text that is no batch table, a cell of the wrong type, an out folder
that cannot be written, broken checkpoints): each ends in one line naming the file or flag, the key and the fix,
exit status 2, nothing written.  Pure unless marked yade."""
import os
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import ROOT, needs_yade
from grainfrac_yade.cli import main
from grainfrac_yade.params.schema import PARAMS_DIR


def _one_line(capsys):
    """The single stderr line of a refused command."""
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    return err[0]


def _cli(*args, cwd=ROOT):
    return subprocess.run([sys.executable, "-m", "grainfrac_yade", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, env=dict(os.environ, OMP_NUM_THREADS="1"))


# ------------------------------------------------------------------ parameter files and flags
@pytest.mark.parametrize("content, argv, message", [
    (b"\x89PNG\r\n\x1a\n\x00\xff\xfe", [],
     "error: {f}: (file): not a text file (byte 0 is not UTF-8); fix: give a TOML parameter file (UTF-8 text), "
     "e.g. " + str(PARAMS_DIR / "presets" / "fem.toml")),
    (b'[specimen]\nwidth = "ten"\n', ["--width", "3e-3"],
     "error: {f}: specimen.width: 'ten' is not a number; fix: give a number [m]"),
    (b'[specimen]\nwidth = "ten"\n', ["--set", "specimen.width=3e-3"],
     "error: {f}: specimen.width: 'ten' is not a number; fix: give a number [m]"),
    (b'[specimen]\nseed_typo = 1\n', [],
     "error: {f}: specimen.seed_typo: unknown key; fix: remove it or correct the spelling"),
])
def test_a_bad_params_file_is_one_line_whatever_overrides_it(tmp_path, capsys, content, argv, message):
    f = tmp_path / "p.toml"
    f.write_bytes(content)
    out = tmp_path / "out"
    assert main(["specimen", "--params", str(f), *argv, "--out", str(out)]) == 2
    assert _one_line(capsys).startswith(message.format(f=f))
    assert not out.exists()


def test_a_folder_given_as_params_file_is_one_line(tmp_path, capsys):
    assert main(["specimen", "--params", str(tmp_path), "--out", str(tmp_path / "out")]) == 2
    assert _one_line(capsys) == (f"error: {tmp_path}: (file): a folder, not a file; fix: give a TOML parameter file; "
                                 f"shipped files are in {PARAMS_DIR}")


@pytest.mark.parametrize("out", ["", "  "])
@pytest.mark.parametrize("command", [["specimen"], ["ucs"], ["creep", "--ratio", "0.5"]])
def test_an_empty_out_is_refused_not_taken_for_the_default(tmp_path, capsys, monkeypatch, command, out):
    monkeypatch.chdir(tmp_path)
    assert main([*command, "--out", out]) == 2
    assert _one_line(capsys) == (f"error: --out {out!r}: an empty folder name; fix: give a folder (e.g. --out "
                                 "results/run1), or leave --out out for the command's default folder")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("seed, ok", [("4294967295", True), ("4294967296", False),
                                      ("100000000000000000000000", False), ("-1", False)])
def test_a_seed_is_limited_to_the_32_bit_range(capsys, seed, ok):
    from grainfrac_yade.cli import build_parser
    argv = ["specimen", "--seed", seed]
    if ok:
        assert build_parser().parse_args(argv).seed == int(seed)
        return
    with pytest.raises(SystemExit) as exc:
        build_parser().parse_args(argv)
    assert exc.value.code == 2
    assert _one_line(capsys) == (f"error: python3 -m grainfrac_yade specimen: argument --seed: {int(seed)}: a seed is a "
                                 "whole number from 0 to 4294967295 (the range of a 32-bit seed; e.g. 1); fix: see "
                                 "python3 -m grainfrac_yade specimen --help")
