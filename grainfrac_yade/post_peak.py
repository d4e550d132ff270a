"""The post-peak rule of the strain-controlled tests (UCS and Brazilian), shared by the running tests and
their analysis: a measured value has dropped past its peak once it lies below a ratio of the peak with
bonds broken since the peak, past a minimum strain.  Pure (no YADE)."""


def dropped_past_peak(value: float, peak: float, broken_now: int, broken_at_peak: int, ratio: float,
                      strain: float = 0.0, min_strain: float = 0.0) -> bool:
    """True if ``value`` < ``ratio`` x ``peak`` with more bonds broken than at the peak, and (``min_strain``
    > 0) at a ``strain`` of ``min_strain`` or more.  This model softens only as bonds break: a drop with no
    break since the peak is the elastic ringing of a specimen set in motion from rest (measured on a
    one-cell-wide column: 3.4 MPa, then below 2.4 MPa, no bond broken), not a post-peak branch; a drop
    before ``min_strain`` (``ucs.stop_min_strain``, ``brazilian.stop_min_strain``) is the start transient."""
    return ((min_strain <= 0 or strain >= min_strain) and value < ratio * peak
            and broken_now > broken_at_peak)


def softened_past_peak(value, peak, broken_now, broken_at_peak, stop_ratio, strain=0.0, min_strain=0.0) -> bool:
    """The end criterion of a strain-controlled test: a positive ``peak`` and :func:`dropped_past_peak` at
    ``stop_ratio`` (``ucs.stop_stress_ratio``, ``brazilian.stop_load_ratio``)."""
    return peak > 0 and dropped_past_peak(value, peak, broken_now, broken_at_peak, stop_ratio, strain, min_strain)
