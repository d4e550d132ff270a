"""The settings the hybrid engine does not read (pure: parameters only).

The hybrid engine relaxes by YADE's dynamic stints where statics give out; its static path is the plain one, so the
static engine's own relaxation settings mean nothing to it.  Every dynamic setting is read by the stints.
"""
from __future__ import annotations

from ..static.settings import override_key

#: Settings of the static engine's relaxation that the hybrid engine does not read.
NOT_USED = ("numerics.static_relaxation", "numerics.static_relaxation_steps")


def not_used_settings(params) -> dict:
    """{key: value} of the settings a hybrid run with ``params`` does not read (its summary's ``settings_not_used``)."""
    return {k: getattr(params.numerics, k.split(".")[1]) for k in NOT_USED}


def warn_not_used(overrides) -> list:
    """One warning line per setting among ``overrides`` (``(key, value)`` pairs or ``section.key=value`` strings)
    that the hybrid engine does not read."""
    return [f"warning: --set {key}: the hybrid engine relaxes by YADE's dynamics and does not use it"
            for key in map(override_key, overrides) if key in NOT_USED]
