"""Which stress the static engine's failure criterion reads: a bond's own, or its whole face's (pure: names and the
one-line refusals).

``numerics.static_failure``:

* ``"bond"`` (the default): paper Eq. 4-5 on each bond's own stress; a face with several bonds
  (``resolution.nodes_per_face``) can fail bond by bond;
* ``"face"``: paper Eq. 4-5 on each face's resultant (the paper's "contact i" read as a whole grain contact, as a
  rigid-block UDEC contact): sigma = sum of the face's bond normal forces / the face's area, tau = |sum of their
  signed shear forces| / the face's area; the face fails as a whole, all its intact bonds at once
  (:mod:`grainfrac_yade.engines.static.face_failure`).  With one bond per face both are the same criterion.

Only the static engine's path has faces that break as a whole; the yade and hybrid engines refuse ``"face"`` (as they
refuse the saw-tooth softening, :mod:`grainfrac_yade.softening`).
"""
from __future__ import annotations

from .errors import GrainfracError, ParameterError
from .softening import SOFTENING_NONE, engine_refusal as softening_refusal

#: The values of ``numerics.static_failure`` (the schema's choices).
FAILURE_BOND, FAILURE_FACE = "bond", "face"


def engine_refusal(params, engine: str) -> str:
    """The one line that refuses face failure on an engine other than the static one ("" where the run asks for the
    bond criterion)."""
    if params.numerics.static_failure == FAILURE_BOND:
        return ""
    return (f"numerics.static_failure = {params.numerics.static_failure!r}: a face breaking as a whole is an event of "
            f"the static engine's path, the {engine} engine breaks bonds one by one; fix: --engine static, or "
            "numerics.static_failure = \"bond\"")


def static_path_refusal(params, engine: str) -> str:
    """The one line refusing what only the static engine's path models (the saw-tooth softening, face failure) on
    ``engine`` ("" where the run asks for neither)."""
    return softening_refusal(params, engine) or engine_refusal(params, engine)


def refuse_static_path_settings(params, engine: str) -> None:
    """Raise :class:`~grainfrac_yade.errors.GrainfracError` with :func:`static_path_refusal`'s line, if any (a scene
    built without the command line's check)."""
    line = static_path_refusal(params, engine)
    if line:
        raise GrainfracError(line)


def check_combination(numerics, origins) -> None:
    """Refuse face failure with the saw-tooth softening (a tooth is a bond's own event; a face's teeth would need a
    face-level envelope, which the path does not have): :class:`~grainfrac_yade.errors.ParameterError`, one line."""
    if numerics.static_failure == FAILURE_FACE and numerics.static_softening != SOFTENING_NONE:
        raise ParameterError(origins.get("numerics.static_failure", "parameters"), "numerics.static_failure",
                             f"{numerics.static_failure!r} with numerics.static_softening = "
                             f"{numerics.static_softening!r}: the saw-tooth teeth are a bond's own, a face has none",
                             "set numerics.static_failure = \"bond\", or numerics.static_softening = \"none\"")


def reading_refusal(params) -> str:
    """The one line refusing a creep test with face failure whose corrosion does not read the face (\"\" where it
    does, or the criterion is the bond's): the bonds of a face must corrode alike to keep one strength, so that the
    face's strength and its failure time are one."""
    if params.numerics.static_failure == FAILURE_BOND or params.stress_corrosion.reading == "face":
        return ""
    return (f"numerics.static_failure = \"face\" with stress_corrosion.reading = "
            f"{params.stress_corrosion.reading!r}: the bonds of a face would corrode apart and the face have no one "
            "strength; fix: stress_corrosion.reading = \"face\", or numerics.static_failure = \"bond\"")
