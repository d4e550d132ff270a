"""The stress servo's law, behind every engine's servo (pure).

The platens close at a speed set from the stress error so that the error would be removed in ``response_steps``
DEM steps on a specimen of axial stiffness E x cross-section / height:

    v = (target - stress) x gain / dt,    gain = height / (E x response_steps),

clipped to +-``max_speed``.  Saturation: a command clipped at +``max_speed`` (the specimen carries so much less
than the target that the servo closes the platens as fast as it may).  ``clipped`` is the sign of the clip of the
last command (+1 closing at the limit, -1 opening at the limit, 0 within the limits); ``closing_clipped_steps``
counts the DEM steps in a row, up to and including the last one, whose command was clipped closing (0 after any
other command): what :func:`.held_relaxation.collapsing` reads, with ``stress`` and ``target``.

The engines' servos: YADE's platen servo (:class:`grainfrac_yade.engines.yade.platens.StressServo`, a driver called
before each DEM step) and the static engine's inertial one (:class:`grainfrac_yade.engines.static.inertial.
HeldServo`) command with :class:`ServoLaw`; the static engine's held stress (:class:`grainfrac_yade.engines.static.
platens.StaticServo`) is solved at its target, not servoed, and shows the same attributes (saturated closing once
the load cannot be regained).
"""
from __future__ import annotations


class ServoLaw:
    """The servo's command and its clip bookkeeping (module doc); ``target`` [Pa], ``gain`` [m/Pa], ``max_speed``
    [m/s] as the engine's servo sets them."""

    def __init__(self, target, gain, max_speed):
        self.target, self.gain, self.max_speed = target, gain, max_speed
        self.stress, self.clipped, self.closing_clipped_steps = 0.0, 0, 0

    def command(self, stress: float, dt: float) -> float:
        """The closing speed [m/s] for the measured ``stress`` [Pa] over a step ``dt`` [s] (and the clip
        bookkeeping)."""
        self.stress = stress
        speed = (self.target - stress) * self.gain / dt
        self.clipped = 1 if speed > self.max_speed else (-1 if speed < -self.max_speed else 0)
        self.closing_clipped_steps = self.closing_clipped_steps + 1 if self.clipped == 1 else 0
        # min/max, not np.clip: the same double, without numpy's per-call overhead (3 % of a creep run's time)
        return min(max(speed, -self.max_speed), self.max_speed)
