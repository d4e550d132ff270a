"""The loads a command line or a batch row gives, checked once for every command: stress flags in MPa, the
confining stress, the creep load from a stress or a driving-stress ratio, and their plausible range."""
from __future__ import annotations

import argparse
import math

from ..errors import GrainfracError
from ..params import FlagOverride


#: Pa per MPa: every stress flag of the CLI is in MPa, every file and batch column in Pa.
PA_PER_MPA = 1e6


#: Largest load, confining stress or reference strength accepted, as a multiple of the specimen's reference
#: strength (calibration.reference_ucs): above it a value is taken for a unit slip (Pa given where MPa is
#: meant is 1e6 times too large), not a test.  Confined peak strengths measured here stay below 2 x it
#: (426 MPa at 20 MPa confinement against 236 MPa).
MAX_STRESS_OVER_REFERENCE = 4.0


#: Smallest creep load (and reference strength) accepted [Pa]: 1 MPa.  Creep tests of granite hold 40 % of the UCS
#: or more (Lajtai & Schmidtke's long-term strength bound lies near 60 %), some 100 MPa; a stress below 1 MPa is a
#: unit slip (a batch column in Pa given as MPa: 160 for 160e6; a CLI flag in MPa given as Pa: 1e-6), and would
#: only hold the specimen unloaded to the creep time limit.
MIN_STRESS_PA = 1e6


def add_confinement_option(parser):
    """``--confinement MPA``: the confining stress sigma_3 (sets confinement.stress)."""
    parser.add_argument("--confinement", type=float, metavar="MPA",
                        help="confining stress sigma_3 [MPa], e.g. 20, held on the side walls (biaxial test; "
                             "confinement.stress, in Pa in files); omit for a uniaxial test")


def confinement_override(args) -> list:
    """The override of ``--confinement MPA`` (none if not given); refuses a value at or below 0 in one line."""
    value = getattr(args, "confinement", None)
    if value is None:
        return []
    if not (math.isfinite(value) and value > 0):
        raise GrainfracError(f"--confinement {value:g} MPa (confinement.stress): a confining stress must be above 0 "
                             "MPa; fix: e.g. --confinement 20, or omit it for a uniaxial test")
    return [FlagOverride("confinement.stress", value * PA_PER_MPA, "--confinement")]


def positive_flag(text: str, what: str, unit: str, si_per_unit: float, example: str) -> float:
    """A finite positive number of ``unit`` from a flag, returned in SI (x ``si_per_unit``); argparse's
    ArgumentTypeError naming ``what`` (a stress, a modulus) otherwise."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not {what} in {unit} (e.g. {example})") from None
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"{text!r}: {what} must be finite and above 0 {unit} (e.g. {example})")
    return value * si_per_unit


def stress_flag(text: str) -> float:
    """argparse type of a stress flag: a number of MPa, returned in Pa."""
    return positive_flag(text, "a stress", "MPa", PA_PER_MPA, "258")


def check_stress_range(params, where: str = "confinement.stress") -> None:
    """Refuse a confining stress above :data:`MAX_STRESS_OVER_REFERENCE` x calibration.reference_ucs (one line;
    ``where``: how the user gave it)."""
    confining, ref = params.confinement.stress, params.calibration.reference_ucs
    if confining > MAX_STRESS_OVER_REFERENCE * ref:
        raise GrainfracError(f"{where}: confining stress {confining / PA_PER_MPA:.4g} MPa is above "
                             f"{MAX_STRESS_OVER_REFERENCE:g} x the reference strength (calibration.reference_ucs = "
                             f"{ref / PA_PER_MPA:.4g} MPa); fix: --confinement is in MPa (e.g. 20), "
                             "confinement.stress in files and batch columns in Pa (e.g. 20e6)")


def positive_int(text: str) -> int:
    """An integer >= 1 (argparse type)."""
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number >= 1 (e.g. 10)")
    return value


def resolve_stress(params, stress=None, ratio=None, ucs=None, cli=False):
    """(axial stress sigma_1 [Pa], ratio, strength used [Pa]); ``stress`` and ``ucs`` in Pa.

    Uniaxial: the ratio is sigma_1 / UCS, the UCS being ``ucs`` or the calibrated mean UCS.  Confined
    (``confinement.stress`` sigma_3 > 0): the ratio is the deviatoric one, (sigma_1 - sigma_3) /
    (sigma_peak - sigma_3), and ``ucs`` must be given: the peak axial stress sigma_peak of the
    compression test at the same sigma_3 (``ucs --confinement``).  ``cli``: name the values as the
    CLI flags give them (MPa) in the messages, else as batch columns (Pa).
    """
    def named(flag, value):   # how the user gave a stress [Pa]
        return f"--{flag} {value / PA_PER_MPA:.4g} MPa" if cli else f"column {flag} = {value:.4g} Pa"
    example = {"stress": "--stress 160" if cli else "stress 160e6", "ucs": "--ucs 258" if cli else "ucs 258e6"}
    confining = params.confinement.stress
    calibrated = params.calibration.reference_ucs
    if stress is None and ratio is None:
        raise GrainfracError("no creep load: give a stress or a driving-stress ratio (CLI --stress MPA / --ratio, "
                             "batch column stress [Pa] / ratio); fix: e.g. ratio 0.7")
    for flag, value in (("stress", stress), ("ucs", ucs)):
        if value is None:
            continue
        if not (math.isfinite(value) and value > 0):
            raise GrainfracError(f"{named(flag, value)}: a stress must be finite and above 0; fix: e.g. "
                                 f"{example[flag]}")
        if value < MIN_STRESS_PA:
            raise GrainfracError(f"{named(flag, value)} is below {MIN_STRESS_PA / PA_PER_MPA:g} MPa, no creep load for "
                                 "granite; fix: CLI stress flags are in MPa, batch columns in Pa: e.g. " + example[flag])
        if value > MAX_STRESS_OVER_REFERENCE * calibrated:
            raise GrainfracError(f"{named(flag, value)} is above {MAX_STRESS_OVER_REFERENCE:g} x the reference "
                                 f"strength (calibration.reference_ucs = {calibrated / PA_PER_MPA:.4g} MPa); fix: "
                                 "CLI stress flags are in MPa, batch columns in Pa: e.g. " + example[flag])
    if confining > 0 and ucs is None:
        raise GrainfracError(f"confinement.stress = {confining:.4g} Pa: the driving-stress ratio refers to the peak "
                             "strength at this confinement; fix: give --ucs (batch column ucs), the peak axial stress "
                             "of `ucs --confinement` at the same confining stress")
    ref = ucs if ucs is not None else calibrated
    if not ref > confining:
        raise GrainfracError(f"{named('ucs', ref)} is not above the confining stress {confining / PA_PER_MPA:.4g} MPa; "
                             "fix: give the peak axial stress at this confinement")
    if stress is None:
        if not (0 < ratio < 1):
            given = f"--ratio {ratio:g}" if cli else f"column ratio = {ratio:g}"
            raise GrainfracError(f"{given}: a driving-stress ratio must lie in (0, 1); fix: e.g. "
                                 f"{'--ratio' if cli else 'ratio'} 0.7")
        stress = confining + ratio * (ref - confining)
        if stress < MIN_STRESS_PA:
            given = f"--ratio {ratio:g}" if cli else f"column ratio = {ratio:g}"
            raise GrainfracError(f"{given} gives {stress / PA_PER_MPA:.4g} MPa, below {MIN_STRESS_PA / PA_PER_MPA:g} MPa, "
                                 f"no creep load for granite; fix: e.g. {'--ratio' if cli else 'ratio'} 0.7")
    if not stress > confining:
        raise GrainfracError(f"{named('stress', stress)}: must be above the confining stress "
                             f"({confining / PA_PER_MPA:.4g} MPa); fix: e.g. {example['stress']}")
    if stress >= ref:
        strength = "the UCS" if confining == 0 else "the peak strength at this confinement"
        raise GrainfracError(f"{named('stress', stress)} is at or above {strength} it refers to "
                             f"({ref / PA_PER_MPA:.4g} MPa): the specimen fails during the ramp; fix: give a stress "
                             "below it (or --ucs)")
    return stress, (stress - confining) / (ref - confining), ref


#: yade-batch columns of a creep row that are not model parameters [Pa or 1; 0 = not given].
CREEP_ROW_COLUMNS = {"ratio": 0.0, "stress": 0.0, "ucs": 0.0}


def creep_name_parts(controls: dict) -> list:
    """The load columns that name a creep row's folder, before its parameters: ratio (or stress), and ucs if given."""
    parts = [("ratio", controls["ratio"])] if float(controls["ratio"]) else [("stress", controls["stress"])]
    return parts + ([("ucs", controls["ucs"])] if float(controls["ucs"]) else [])
