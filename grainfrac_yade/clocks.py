"""Creep clocks: creep time (the stress-corrosion time axis) kept apart from DEM time.

:class:`PaperClock` is the paper's adaptive creep step (Eq. 8); :class:`EventClock` keeps the creep
time of the event clock, which jumps straight to the next bond failure under frozen stresses (the
interval itself is :func:`grainfrac_yade.law.creep_step`: the degradation law decides it).  Both are
plain validated objects with ``state_dict()`` / ``from_state()`` for checkpoints; nothing here knows
about YADE or about a degradation law.
"""
import math

import numpy as np

from grainfrac_yade.errors import NumericalFailure

STATE_VERSION = 1  # bump when a state_dict layout changes; from_state refuses other versions


def _number(name, value, fix, nan_ok=False):
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number (got {value!r}); {fix}") from None
    if math.isnan(x) and not nan_ok:
        raise ValueError(f"{name} must not be NaN; {fix}")
    return x


def _check_state(state, kind):
    if not isinstance(state, dict) or state.get("kind") != kind:
        raise ValueError(f"state must be a dict with kind={kind!r} (got {state!r:.80})")
    if state.get("version") != STATE_VERSION:
        raise ValueError(f"state version must be {STATE_VERSION} (got {state.get('version')!r});"
                         " the checkpoint was written by another release")


class PaperClock:
    """Adaptive creep step of paper Eq. 8.

    dt_b = min(2 dt_{b-1}, dt_max) if the unbalanced force F_u < threshold, else dt_min; the
    first step (and the first after :meth:`reset_step`) is dt_min. "Balanced" means F_u below
    the threshold and nothing else (:meth:`balanced`): the creep loop counts DEM steps without
    balance against the same test, so the step never grows on a state the loop calls unsettled.

    Parameters
    ----------
    dt_min : float
        Smallest creep step [s], > 0 (paper: 1e-5 s).
    dt_max : float
        Largest creep step [s], >= dt_min, finite (paper: 1e4 s).
    unbalanced_force_threshold : float
        F_u below which the step doubles [N], > 0 (paper: 100 N).
    """

    KIND = "PaperClock"

    def __init__(self, dt_min=1e-5, dt_max=1e4, unbalanced_force_threshold=100.0):
        lo = _number("dt_min", dt_min, "give a time step in s, e.g. 1e-5")
        hi = _number("dt_max", dt_max, "give a time step in s, e.g. 1e4")
        thr = _number("unbalanced_force_threshold", unbalanced_force_threshold,
                      "give a force in N, e.g. 100")
        if not math.isfinite(hi):
            raise ValueError(f"dt_max must be finite (got {dt_max!r}); fix: e.g. 1e4 s")
        if not 0 < lo <= hi:
            raise ValueError(f"dt_min must be > 0 and <= dt_max (got dt_min={dt_min!r}, "
                             f"dt_max={dt_max!r}); fix: choose 0 < dt_min <= dt_max")
        if not (0 < thr < math.inf):
            raise ValueError(f"unbalanced_force_threshold must be finite and > 0 N "
                             f"(got {unbalanced_force_threshold!r}); fix: e.g. 100 N")
        self.dt_min, self.dt_max, self.unbalanced_force_threshold = lo, hi, thr
        self._creep_time = 0.0
        self._dt = None  # last step [s]; None: the next step is the first
        self._n_steps = 0

    @property
    def creep_time(self):
        """Accumulated creep time [s]."""
        return self._creep_time

    @property
    def dt(self):
        """Last creep step [s], or None before the first step."""
        return self._dt

    @property
    def n_steps(self):
        """Number of creep steps taken."""
        return self._n_steps

    def next_step(self, unbalanced_force):
        """Take one creep step (paper Eq. 8), advance creep_time by it and return it.

        Parameters
        ----------
        unbalanced_force : float
            F_u after the last DEM relaxation [N], finite and >= 0 (see :meth:`balanced`).

        Returns
        -------
        float
            dt_b [s], in [dt_min, dt_max].
        """
        balanced = self.balanced(unbalanced_force)  # checked even where the step is dt_min anyway
        if self._dt is None or not balanced:
            dt = self.dt_min
        else:
            dt = min(2.0 * self._dt, self.dt_max)
        self._dt = dt
        self._creep_time += dt
        self._n_steps += 1
        return dt

    def balanced(self, unbalanced_force):
        """True if F_u is below the threshold: the step may double, and the state counts as settled.

        Parameters
        ----------
        unbalanced_force : float
            F_u [N, or relative], >= 0. NaN or inf (the DEM blew up) raises NumericalFailure.
        """
        f = _number("unbalanced_force", unbalanced_force, "pass the DEM's unbalanced force", nan_ok=True)
        if not math.isfinite(f):
            raise NumericalFailure(f"unbalanced force is {f} (the DEM blew up)")
        if f < 0:
            raise ValueError(f"unbalanced_force must be >= 0 (got {f!r}); pass a magnitude")
        return f < self.unbalanced_force_threshold

    def advance_many(self, unbalanced_forces):
        """Take one step per value of ``unbalanced_forces`` [N]; return the summed creep time [s].

        For degradation applied every k DEM steps: the caller applies Eq. 7 once for the
        returned total (exact under frozen stresses, as the rate is then constant).
        """
        total = 0.0
        for f in np.asarray(unbalanced_forces, dtype=float).ravel():
            total += self.next_step(f)
        return total

    def reset_step(self):
        """Make the next step dt_min again (e.g. after a bond broke); creep_time is kept."""
        self._dt = None

    def state_dict(self):
        """JSON-serialisable state; :meth:`from_state` restores it bit-identically."""
        return {"kind": self.KIND, "version": STATE_VERSION, "dt_min": self.dt_min,
                "dt_max": self.dt_max,
                "unbalanced_force_threshold": self.unbalanced_force_threshold,
                "creep_time": self._creep_time, "dt": self._dt, "n_steps": self._n_steps}

    @classmethod
    def from_state(cls, state):
        """Rebuild a clock from :meth:`state_dict` output (validated)."""
        _check_state(state, cls.KIND)
        clock = cls(state["dt_min"], state["dt_max"], state["unbalanced_force_threshold"])
        t = _number("creep_time", state["creep_time"], "state is corrupt")
        if not (0 <= t < math.inf):
            raise ValueError(f"creep_time must be finite and >= 0 s (got {t!r})")
        dt = state["dt"]
        if dt is not None and not (clock.dt_min <= _number("dt", dt, "state is corrupt")
                                   <= clock.dt_max):
            raise ValueError(f"dt must be None or in [dt_min, dt_max] (got {dt!r})")
        n = state["n_steps"]
        if not (isinstance(n, int) and n >= 0):
            raise ValueError(f"n_steps must be an int >= 0 (got {n!r})")
        clock._creep_time, clock._dt, clock._n_steps = t, None if dt is None else float(dt), n
        return clock


class EventClock:
    """Creep time of the event-driven clock: intervals that jump to the next bond failure.

    The law decides each interval (:func:`grainfrac_yade.law.creep_step`, which reads
    ``time_limit``, ``creep_time`` and ``max_strength_loss_fraction`` from here); this object adds
    it to the creep time and counts intervals, events and failed bonds.

    Parameters
    ----------
    max_strength_loss_fraction : float
        Laws that change stiffness (the area law): the interval ends when a bond has lost this
        fraction of its intact capacity, so the DEM can redistribute the load [-], in (0, 1).
    time_limit : float
        Creep time at which the run ends [s], > 0, may be inf.
    """

    KIND = "EventClock"

    def __init__(self, max_strength_loss_fraction=0.1, time_limit=math.inf):
        f = _number("max_strength_loss_fraction", max_strength_loss_fraction, "e.g. 0.1")
        if not 0 < f < 1:
            raise ValueError(f"max_strength_loss_fraction must be in (0, 1) "
                             f"(got {max_strength_loss_fraction!r}); fix: e.g. 0.1")
        lim = _number("time_limit", time_limit, "give seconds or inf")
        if not lim > 0:
            raise ValueError(f"time_limit must be > 0 s or inf (got {time_limit!r})")
        self.max_strength_loss_fraction, self.time_limit = f, lim
        self._creep_time = 0.0
        self._n_intervals = self._n_events = self._n_failures = 0

    creep_time = property(lambda self: self._creep_time, doc="Accumulated creep time [s].")
    n_intervals = property(lambda self: self._n_intervals, doc="Intervals advanced.")
    n_events = property(lambda self: self._n_events, doc="Intervals that ended in a failure.")
    n_failures = property(lambda self: self._n_failures, doc="Bonds failed at interval ends.")

    @property
    def finished(self):
        """True once creep_time has reached time_limit."""
        return self._creep_time >= self.time_limit

    def advance(self, dt, failing_index=()):
        """Add dt [s] to creep_time and count the interval (and its failures); return creep_time."""
        d = _number("dt", dt, "pass the dt returned by next_interval")
        if not 0 <= d < math.inf:
            raise ValueError(f"dt must be finite and >= 0 s (got {dt!r}); inf means stop")
        n_fail = len(np.atleast_1d(failing_index))
        self._creep_time += d
        self._n_intervals += 1
        self._n_events += n_fail > 0
        self._n_failures += n_fail
        return self._creep_time

    def state_dict(self):
        """JSON-serialisable state (time_limit inf is stored as None)."""
        return {"kind": self.KIND, "version": STATE_VERSION,
                "max_strength_loss_fraction": self.max_strength_loss_fraction,
                "time_limit": None if math.isinf(self.time_limit) else self.time_limit,
                "creep_time": self._creep_time, "n_intervals": self._n_intervals,
                "n_events": self._n_events, "n_failures": self._n_failures}

    @classmethod
    def from_state(cls, state):
        """Rebuild a clock from :meth:`state_dict` output (validated)."""
        _check_state(state, cls.KIND)
        lim = state["time_limit"]
        clock = cls(state["max_strength_loss_fraction"], math.inf if lim is None else lim)
        t = _number("creep_time", state["creep_time"], "state is corrupt")
        if not 0 <= t < math.inf:
            raise ValueError(f"creep_time must be finite and >= 0 s (got {t!r})")
        counts = [state[k] for k in ("n_intervals", "n_events", "n_failures")]
        if not all(isinstance(n, int) and n >= 0 for n in counts):
            raise ValueError(f"interval/event/failure counters must be ints >= 0 (got {counts})")
        clock._creep_time = t
        clock._n_intervals, clock._n_events, clock._n_failures = counts
        return clock
