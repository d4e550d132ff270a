"""Default results are unchanged to the last bit: fresh creep runs of the default law (paper Eq. 7 on
strength, rigid cells) against runs stored at commit 7e91240 (tests/reference_creep.py).

Tolerance 0: one thread (OMP_NUM_THREADS=1, the conftest loader), the same specimen, parameters and
seed, and the same float operations in the same order give the same doubles on this platform
(x86-64, Debian's numpy 1.24 and YADE 2023.02a); repeated runs were checked equal.  A different
BLAS, numpy or CPU may round differently: regenerate the files there with
``/usr/bin/python3 tests/reference_creep.py write`` at a commit known to be right.
About 25 s (event clock, 4 x 8 mm, seeds 1 and 2) and 35 s (paper clock, 3 x 6 mm) alone."""
import pytest

from conftest import needs_yade
from reference_creep import RUNS, run, stored

pytestmark = [needs_yade, pytest.mark.yade]


@pytest.mark.parametrize("name", list(RUNS))
def test_default_law_reproduces_the_stored_run_bit_for_bit(tmp_path, name):
    summary, history, cracks = run(name, tmp_path / name)
    ref_summary, ref_history, ref_cracks = stored(name)
    assert summary == ref_summary
    assert list(history.columns) == list(ref_history.columns) and len(history) == len(ref_history)
    for column in history:
        assert history[column].tolist() == ref_history[column].tolist(), column
    assert cracks.equals(ref_cracks)
