"""The platens, the held stress and the confinement of a static scene (:mod:`.scene`): what the test protocols drive
through :class:`grainfrac_yade.engines.PlatenDrive` (pure numpy).

* :class:`StaticPlatens`: displacement control of the platen closure d (top -d/2, bottom +d/2, smooth platens);
  strains and the platen stress are read off the scene's converged state; ``hold_stress`` switches to load control;
* :class:`StaticServo`: the held platen stress of a creep hold (solved at its target, not servoed);
* :class:`StaticConfinement`: a constant lateral traction on the side nodes (a dead load of the equilibrium).
"""
from __future__ import annotations

import math

import numpy as np

from ...errors import GrainfracError


class StaticPlatens:
    """The platens of a static scene (:class:`grainfrac_yade.engines.PlatenDrive`): the closure d is the core's
    control; strains and the platen stress are read off its converged state."""

    name = "Platens"

    def __init__(self, scene: "StaticScene"):
        net = scene.net
        self.scene = scene
        self.width, self.height = net.width, net.height
        self.velocity = 0.0
        # reference positions (what a checkpoint keeps of YADE's platens): the closure is measured from them
        self.y0_top, self.y0_bottom, self.x0_gap = net.height, 0.0, net.width

    def hold_stress(self, target: float, young: float, response_steps: int, max_speed: float) -> "StaticServo":
        """Load control at ``target`` [Pa] from here on (module doc): a :class:`StaticServo`, listed among the scene's
        drivers; ``young`` and ``response_steps`` only set its nominal gain (the held stress is solved, not servoed)."""
        if not (math.isfinite(target) and target > 0):
            raise GrainfracError(f"static engine: a held platen stress must be finite and > 0 Pa (got {target!r}); "
                                 "fix: a positive creep stress")
        gain = self.height / (young * response_steps) if young > 0 and response_steps > 0 else 0.0
        # a hold starts from a fresh factor of the ramp's end state, not from the ramp's low-rank history
        self.scene.eq.forget_factor()
        return self._servo(StaticServo(self.scene, float(target), gain, float(max_speed)))

    def resume_hold(self, saved: dict) -> "StaticServo":
        """:meth:`hold_stress` as a checkpoint saved it (``saved``: the servo's attributes by name; the hold's
        own state, failure included, came back with the scene's file)."""
        servo = StaticServo(self.scene, float(saved["target"]), float(saved["gain"]), float(saved["max_speed"]))
        servo.closing_clipped_steps = int(saved.get("closing_clipped_steps", 0))
        return self._servo(servo)

    def _servo(self, servo: "StaticServo") -> "StaticServo":
        scene = self.scene
        scene.drivers = [d for d in scene.drivers if not isinstance(d, StaticServo)] + [servo]
        scene.hold_target = servo.target
        return servo

    def set_axial_velocity(self, closing_speed: float) -> None:
        """The platens approach each other at ``closing_speed`` [m/s of the load parameter]."""
        self.velocity = float(closing_speed)

    def shift(self, closing: float) -> None:
        """Close the platens by ``closing`` [m] in one jump, solved along the path (breaks and cascades)."""
        self.scene.move_to(self.scene.state.closure + float(closing))

    def axial_strain(self) -> float:
        return self.scene.state.closure / self.height

    def lateral_strain(self) -> float:
        """Change of the side nodes' mean distance over the width (compression positive) [1]."""
        net, u = self.scene.net, self.scene.state.u
        ux = np.where(net.dofs[:, 0] >= 0, u[np.maximum(net.dofs[:, 0], 0)], 0.0)
        gap = (ux[net.right].mean() if net.right.any() else 0.0) - (ux[net.left].mean() if net.left.any() else 0.0)
        return -gap / self.width

    def axial_stress(self) -> float:
        return float(self.scene.state.stress)

    def state_dict(self) -> dict:
        return {"velocity": self.velocity, "y0_top": float(self.y0_top), "y0_bottom": float(self.y0_bottom),
                "x0_gap": float(self.x0_gap), "reaction_pa": self.axial_stress(),
                "closure": float(self.scene.state.closure)}

    def restore_state(self, saved: dict) -> None:
        """After a restore: the speed and the reference positions of :meth:`state_dict` (nothing to fetch: the
        closure and the stress are the restored state's)."""
        self.velocity, self.y0_top, self.y0_bottom, self.x0_gap = (saved["velocity"], saved["y0_top"],
                                                                   saved["y0_bottom"], saved["x0_gap"])


class StaticServo:
    """The held platen stress of a static scene: what the creep protocol reads of a stress servo.  The stress is
    solved at the target (module doc), so the servo never clips, unless the failure rule says the target cannot be
    regained: then it reads as saturated closing (``clipped`` +1, ``closing_clipped_steps`` growing by the steps
    asked of the scene), which is how a platen that cannot hold its load looks to the protocol."""

    name = "StaticStressHold"

    def __init__(self, scene: "StaticScene", target: float, gain: float, max_speed: float):
        self.scene, self.target, self.gain, self.max_speed = scene, target, gain, max_speed
        self.closing_clipped_steps = 0

    @property
    def stress(self) -> float:
        """The axial stress of the solved state [Pa]."""
        return float(self.scene.state.stress)

    @property
    def clipped(self) -> int:
        return 1 if self.scene.hold_failure else 0

    def count(self, n_steps: int) -> None:
        """``n_steps`` asked of the scene: saturated closing while the held load is lost, none otherwise."""
        self.closing_clipped_steps = self.closing_clipped_steps + int(n_steps) if self.scene.hold_failure else 0

    def state_dict(self) -> dict:
        return {"target": self.target, "gain": self.gain, "max_speed": self.max_speed, "stress": self.stress,
                "clipped": self.clipped, "closing_clipped_steps": self.closing_clipped_steps}


class StaticConfinement:
    """Constant lateral traction sigma_3 on the side nodes (a dead load of the equilibrium)."""

    name = "Confinement"

    def __init__(self, scene: "StaticScene", stress: float):
        self.scene, self.stress = scene, float(stress)
        self.apply()

    def apply(self):
        """Make the scene's equilibrium carry the traction (again after a restore)."""
        self.scene.set_confinement(self.stress)

    def total_force(self) -> float:
        """Sum of the inward forces on both sides [N] (2 x sigma_3 x height x thickness)."""
        return float(np.abs(self.scene.net.confinement_force(self.stress)).sum())
