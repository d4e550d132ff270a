"""The post-peak rule shared by the UCS and Brazilian tests and their analysis (no YADE)."""
from grainfrac_yade.post_peak import dropped_past_peak, softened_past_peak


def test_a_drop_needs_the_ratio_new_breaks_and_the_minimum_strain():
    assert dropped_past_peak(69.0, 100.0, 11, 10, 0.7)
    assert not dropped_past_peak(70.0, 100.0, 11, 10, 0.7)      # at the ratio, not below it
    assert not dropped_past_peak(10.0, 100.0, 10, 10, 0.7)      # no break since the peak: elastic ringing
    assert not dropped_past_peak(10.0, 100.0, 11, 10, 0.7, strain=1e-4, min_strain=2e-4)
    assert dropped_past_peak(10.0, 100.0, 11, 10, 0.7, strain=2e-4, min_strain=2e-4)


def test_a_minimum_strain_of_zero_reads_no_strain_and_the_stop_needs_a_peak():
    assert dropped_past_peak(10.0, 100.0, 11, 10, 0.7, strain=-1e-9, min_strain=0.0)
    assert not softened_past_peak(-1.0, 0.0, 1, 0, 0.7)
    assert dropped_past_peak(-1.0, 0.0, 1, 0, 0.7)
    assert softened_past_peak(69.0, 100.0, 11, 10, 0.7)
