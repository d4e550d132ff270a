"""The parameter schema: every section's typed fields with unit, check and meaning, and what a valid value is.

Units are SI; friction angles are given in degrees in files (``*_deg`` keys) and exposed in radians.
Mixed mineral pairs take the arithmetic average of the two pure-mineral rows of Table 2 (paper
section 3.1) unless the files give the pair explicitly (:func:`average_contact`).
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Mapping

from ..errors import ParameterError
from ..law import LAW_NAMES
from ..law.readings import READING_NAMES
from .values import NEAREST_KEY_CUTOFF, RETIRED_VALUES, _check_value, nearest_key

PARAMS_DIR = Path(__file__).resolve().parents[2] / "params"


DEFAULT_FILES = ("ldb_granite.toml", "stress_corrosion.toml", "numerics.toml", "loading.toml",
                 "calibration.toml")


#: Tolerance on the sum of area fractions (they are printed to 3 decimals in the paper).
FRACTION_SUM_TOLERANCE = 1e-6


def _spec(unit: str, check: str, doc: str = "", choices: tuple = ()):
    """Field metadata: SI unit, validation rule and meaning."""
    return field(metadata={"unit": unit, "check": check, "doc": doc, "choices": choices})


@dataclass(frozen=True, kw_only=True)
class SpecimenParams:
    """Specimen geometry (paper section 3.1)."""
    width: float = _spec("m", "positive", "specimen width")
    height: float = _spec("m", "positive", "specimen height")
    thickness: float = _spec("m", "positive", "layer thickness (2D) or box depth (3D)")
    grain_size: float = _spec("m", "positive", "equivalent diameter of a Voronoi cell")
    lloyd_iterations: int = _spec("1", "nonnegative_int", "Lloyd relaxations of the seeds: the lever on the "
                                  "spread of grain sizes, which they narrow (CV of the cells' equivalent diameter "
                                  "on the paper's specimen: 0.27 at 0 = Poisson-Voronoi, 0.16 at 2, 0.12 at 5, 0.09 "
                                  "at 10; docs/studies/lab_bands.md); no value widens it beyond 0's")
    dimension: int = _spec("1", "choice", "2 = plane model, 3 = box", (2, 3))
    min_edge_fraction: float = _spec("1", "fraction_below_half", "regularisation: interior Voronoi edges shorter "
                                     "than this fraction of grain_size are collapsed (their two vertices merged) "
                                     "before minerals are allocated; plane specimens only; 0 = off (the plain "
                                     "Voronoi cells). Source: 3DEC's block edge tolerance, UDEC's minimum edge "
                                     "length, Neper's regularisation (Quey, Dawson & Barbe 2011)")


@dataclass(frozen=True, kw_only=True)
class GrainParams:
    """Elastic, unbreakable grain of one mineral (paper Table 1)."""
    young: float = _spec("Pa", "positive", "Young's modulus E")
    poisson: float = _spec("1", "poisson", "Poisson's ratio")
    density: float = _spec("kg/m3", "positive", "density")

    @property
    def shear_modulus(self) -> float:
        """Shear modulus G = E / (2 (1 + nu)) [Pa]."""
        return self.young / (2.0 * (1.0 + self.poisson))


@dataclass(frozen=True, kw_only=True)
class ContactParams:
    """Elasto-plastic Mohr-Coulomb contact with tension cut-off (paper Table 2, Eq. 4-5)."""
    normal_stiffness: float = _spec("Pa/m", "positive", "contact normal stiffness k_n")
    shear_stiffness_ratio: float = _spec("1", "positive", "k_s / k_n")
    tensile_strength: float = _spec("Pa", "positive", "tensile strength J^T")
    residual_tensile_strength: float = _spec("Pa", "nonnegative", "residual tensile strength J^T_r")
    cohesion: float = _spec("Pa", "positive", "cohesion J^C")
    residual_cohesion: float = _spec("Pa", "nonnegative", "residual cohesion J^C_r")
    friction_angle_deg: float = _spec("deg", "angle", "friction angle phi")
    residual_friction_ratio: float = _spec("1", "unit_interval", "phi_r / phi")

    @property
    def shear_stiffness(self) -> float:
        """Contact shear stiffness k_s = k_n * (k_s/k_n) [Pa/m]."""
        return self.normal_stiffness * self.shear_stiffness_ratio

    @property
    def friction_angle(self) -> float:
        """Friction angle phi [rad]."""
        return math.radians(self.friction_angle_deg)

    @property
    def residual_friction_angle(self) -> float:
        """Residual friction angle phi_r = phi * (phi_r/phi) [rad] (Table 2: ratio 0.5)."""
        return self.friction_angle * self.residual_friction_ratio


@dataclass(frozen=True, kw_only=True)
class ResolutionParams:
    """How finely a Voronoi cell is resolved by spheres."""
    spheres_per_cell: int = _spec("1", "positive_int", "target spheres per cell clump; 1 = one sphere")
    grain_model: str = _spec("", "choice", "rigid: each cell one rigid body; fem: each cell a cluster of "
                             "spheres at the nodes of constant-strain finite elements with its mineral's Table 1 "
                             "moduli", ("rigid", "fem"))
    nodes_per_face: int = _spec("1", "positive_int", "fem cells: breakable bonds per "
                                "Voronoi face (ignored by rigid cells)")
    cell_rings: int = _spec("1", "positive_int", "fem cells: radial refinement of each cell's triangle mesh: the "
                            "boundary ring of nodes repeated at fractions k / cell_rings of the way to the centroid "
                            "(grainfrac_yade.geometry.grainmesh); 1 = one fan of triangles about the centroid; "
                            "rigid cells take only 1")
    cell_ring_growth: float = _spec("1", "positive", "fem cells with cell_rings > 1: thickness ratio of successive "
                                    "rings from the boundary inwards (geometric grading; "
                                    "grainfrac_yade.geometry.grainmesh.ring_fractions); 1 = uniform rings")
    contact_inset: float = _spec("1", "unit_interval_open", "fem cells: fraction of the way from a "
                                 "face node to its cell's centroid at which the node's sphere sits (the two "
                                 "spheres of a bond are distinct bodies a short gap apart)")


@dataclass(frozen=True, kw_only=True)
class NumericsParams:
    """DEM integration knobs, and the engine that computes the scene."""
    engine: str = _spec("", "choice", "mechanical engine of the scene (grainfrac_yade.engines): yade = YADE's "
                        "explicit DEM with dynamic relaxation; static = static equilibrium between bond failures (grainfrac_yade.engines.static: "
                        "no inertia, no loading rate); hybrid = static, with YADE's dynamics where the static "
                        "equilibrium gives out or a cascade grows (grainfrac_yade.engines.hybrid)", ("yade", "static", "hybrid"))
    static_relaxation: str = _spec("", "choice", "static engine: what a held-load regain or a displacement-"
                                   "controlled path does where no static status set settles: inertial (the default) = "
                                   "explicit dynamics of the same network (masses of the grain model with "
                                   "numerics.density_scale, numerics.damping, the creep protocol's servo, equilibrium "
                                   "and collapse criteria and relaxation budget; grainfrac_yade.engines.static.inertial); "
                                   "overdamped = implicit overdamped relaxation to rest or to the failure rule "
                                   "(grainfrac_yade.engines.static.damped), and only then the engine gives out; none = the "
                                   "engine gives out there (a numerical failure).  The hybrid engine does not read it "
                                   "(YADE's dynamic stints relax there)", ("none", "overdamped", "inertial"))
    static_relaxation_steps: int = _spec("1", "positive_int", "static_relaxation = overdamped: pseudo-time steps one "
                                         "relaxation may take before the engine gives out there")
    static_low_rank_contacts: int = _spec("1", "positive_int", "static engine: contacts whose status may differ from "
                                          "the kept factor's before the tangent is factorised anew (below it, a "
                                          "low-rank Woodbury update of the kept factor; "
                                          "grainfrac_yade.engines.static.tangent); changes results at round-off")
    static_update_columns: str = _spec("", "choice", "static engine: how a low-rank update's K^-1 U columns are made: "
                                       "changes = both U columns of a changed contact for each status it takes; rows "
                                       "= each of its rows once per factor, combined with the change (fewer "
                                       "back-substitutions; results change at round-off)", ("changes", "rows"))
    static_condensation: str = _spec("", "choice", "static engine, fem cells: none = the full free system; "
                                     "cell_interiors = each cell's interior nodes (no bond, no platen) condensed out "
                                     "exactly once, the factors, back-substitutions and low-rank updates on the "
                                     "cells' boundary dofs alone (grainfrac_yade.engines.static.condensation; results "
                                     "change at round-off); refused with rigid cells (no interior)",
                                     ("none", "cell_interiors"))
    static_softening: str = _spec("", "choice", "static engine: none = an intact bond breaks at paper Eq. 4-5; sawtooth = it softens by "
                                  "saw-tooth teeth first (grainfrac_yade.softening); refused by the yade and hybrid engines", ("none", "sawtooth"))
    static_softening_teeth: int = _spec("1", "positive_int", "static_softening = sawtooth: teeth N of a bond; 1 = brittle")
    static_softening_ductility: float = _spec("1", "at_least_one", "static_softening = sawtooth: ultimate over peak separation mu; 1 = brittle")
    static_failure: str = _spec("", "choice", "static engine: bond = paper Eq. 4-5 on each bond's own stress (a face with several bonds fails bond by bond); face = on each face's resultant (summed bond forces over the face's area), the face failing as a whole (grainfrac_yade.failure_criterion; a prototype, untested at scale); refused by the yade and hybrid engines, with static_softening = sawtooth, and in a creep test unless stress_corrosion.reading = face", ("bond", "face"))
    handover_cascade_bonds: int = _spec("1", "nonnegative_int", "hybrid engine: bonds one static cascade may break "
                                        "before YADE's dynamics take over from its state; 0 = only where the static "
                                        "equilibrium gives out")
    stint_min_crossings: float = _spec("1", "nonnegative", "hybrid engine: elastic wave crossings a dynamic stint runs "
                                       "before its equilibrium check may end it (the time the released energy needs "
                                       "to reach the whole specimen); 0 = the check from the first period on")
    damping: float = _spec("1", "unit_interval_open", "Cundall non-viscous damping")
    timestep_safety: float = _spec("1", "unit_interval_open", "fraction of the critical time step")
    density_scale: float = _spec("1", "positive", "mass scaling factor for quasi-static runs")
    step_floor_quantile: float = _spec("1", "fraction", "per-cell mass scaling: the cells whose own critical DEM "
                                       "step lies below this quantile of all cells' steps get their mass and "
                                       "inertia multiplied so that their step equals it (statics unchanged; the "
                                       "DEM step of the scene is then that quantile's); 0 = off")
    verlet_fraction: float = _spec("1", "positive", "the collider's Verlet distance (InsertionSortCollider."
                                   "verletDist) as a fraction of the sphere radius named by verlet_radius_quantile: "
                                   "bounding boxes are enlarged by it, and the collider sorts again only once a body "
                                   "has moved farther (YADE's default: 0.5)")
    verlet_radius_quantile: float = _spec("1", "fraction", "quantile of the sphere radii the Verlet distance refers "
                                          "to: 0 = the smallest sphere (YADE's own rule), 0.5 = the median sphere")
    keep_intact_joints: bool = _spec("", "bool", "bonds on their face's plane (fem cells, YADE's smooth joints): "
                                     "keep an intact bond from being erased once the path its faces slid in all "
                                     "exceeds twice its smaller sphere's radius (YADE's rule for a broken joint); "
                                     "false: YADE's rule for intact bonds too")
    checkpoint_interval: float = _spec("s", "nonnegative",
                                       "wall time between checkpoints of a long run (UCS, Brazilian and creep "
                                       "tests, for --resume DIR); 0 = none, but a creep run's at the end of its "
                                       "ramp; does not change results")


@dataclass(frozen=True, kw_only=True)
class StressCorrosionParams:
    """Stress corrosion of bonds (paper Eq. 7 and the laws of :mod:`grainfrac_yade.law`) and its creep
    clocks (paper Eq. 8 and ours)."""
    enabled: bool = _spec("", "bool", "stress corrosion on (creep tests); off: the load is only held")
    law: str = _spec("", "choice", "degradation law: hillig_charles = paper Eq. 7 on strength; normalised = "
                     "exponent on stress/strength (Potyondy 2007); area = corrosion shrinks the bond area",
                     LAW_NAMES)
    reading: str = _spec("", "choice", "the stress that drives Eq. 7's rate: node = each bond's own F/A (UDEC's "
                         "sub-contacts); face = the face's F/L over its whole area (failure stays per bond)",
                         READING_NAMES)
    beta1: float = _spec("Pa/s", "positive", "rate constant beta1 (paper Eq. 7)")
    beta2: float = _spec("1/Pa", "positive", "stress sensitivity beta2 (paper Eq. 7; laws hillig_charles, area)")
    beta2_normalised: float = _spec("1", "positive", "stress sensitivity on stress/strength (law normalised)")
    threshold_ratio: float = _spec("1", "fraction_below_one", "activation threshold: no corrosion while the driving "
                                   "stress is below this fraction of the bond's strength (Potyondy 2007); 0 = off")
    threshold_stress: float = _spec("Pa", "nonnegative", "activation threshold: no corrosion while the driving "
                                    "stress is below this stress (Potyondy 2007's sigma_A); 0 = off")
    clock: str = _spec("", "choice", "creep clock", ("event", "paper"))
    dt_min: float = _spec("s", "positive", "smallest creep step (paper Eq. 8)")
    dt_max: float = _spec("s", "positive", "largest creep step (paper Eq. 8)")
    unbalanced_force_threshold: float = _spec("N", "positive",
                                              "F_u threshold per metre of thickness (paper Eq. 8, UDEC 2D)")
    relative_unbalanced_force_threshold: float = _spec("1", "positive",
                                                       "F_u threshold as mean resultant / mean bond force")
    unbalanced_force_reference: str = _spec("", "choice", "F_u absolute [N] or relative",
                                            ("absolute", "relative"))
    engine_period: int = _spec("1", "positive_int", "DEM steps between applications of the law")
    unbalanced_engine_period: int = _spec("1", "positive_int", "paper clock: DEM steps between applications of the "
                                          "law while F_u is at or above the threshold (the step sits at dt_min)")
    max_strength_loss_fraction: float = _spec("1", "unit_interval_open",
                                              "event clock: largest relative strength loss per interval")
    creep_time_limit: float = _spec("s", "positive", "creep time after which a run stops unfailed")
    rate_form: str = _spec("", "choice", "beta: beta1/beta2 as given; physical: from Eq. 6 at temperature",
                           ("beta", "physical"))
    rate_prefactor: float = _spec("Pa/s", "nonnegative", "lambda_r v0 of paper Eq. 6 (rate_form physical)")
    activation_energy: float = _spec("J/mol", "nonnegative",
                                     "E + V_m gamma/rho of paper Eq. 6 (rate_form physical)")
    activation_volume: float = _spec("m^3/mol", "nonnegative", "V of paper Eq. 6 (rate_form physical)")
    temperature: float = _spec("K", "positive", "absolute temperature T of paper Eq. 6 (rate_form physical)")


def unbalanced_threshold(sc: "StressCorrosionParams") -> float:
    """The F_u threshold of the paper clock for the chosen reference (absolute N/m or relative)."""
    if sc.unbalanced_force_reference == "absolute":
        return sc.unbalanced_force_threshold
    return sc.relative_unbalanced_force_threshold


@dataclass(frozen=True, kw_only=True)
class UcsParams:
    """Strain-controlled uniaxial compression with rigid platens."""
    strain_rate: float = _spec("1/s", "positive", "axial strain rate of the platens (DEM time)")
    stop_stress_ratio: float = _spec("1", "unit_interval_open", "stop when stress falls below this x peak")
    stop_min_strain: float = _spec("1", "nonnegative", "the post-peak stop applies only once the axial strain "
                                   "has passed this (a drop in the start transient is not the peak)")
    max_strain: float = _spec("1", "positive", "stop at this axial strain")
    record_strain_increment: float = _spec("1", "positive", "axial strain between history rows")
    platen_lateral: str = _spec("", "choice", "platen-end cells free (smooth) or fixed (rough) laterally",
                                ("free", "fixed"))


@dataclass(frozen=True, kw_only=True)
class CreepParams:
    """Constant-load creep test (paper section 4.1): ramp, servo hold, equilibrium and failure."""
    ramp_strain_rate: float = _spec("1/s", "positive", "strain rate of the ramp to the creep load (DEM time)")
    servo_response_steps: int = _spec("1", "positive_int", "DEM steps in which the servo removes a stress error")
    servo_max_strain_rate: float = _spec("1/s", "positive", "largest platen strain rate the servo may use")
    servo_response_crossings: float = _spec("1", "nonnegative",
                                            "the servo's response in elastic wave crossings of the specimen's "
                                            "height, where longer than servo_response_steps; 0 = steps alone")
    equilibrium_tolerance: float = _spec("1", "unit_interval_open",
                                         "equilibrium: mean unbalanced force on free cells / mean bond force")
    stress_tolerance: float = _spec("1", "unit_interval_open", "equilibrium: |held - target| / target")
    check_period: int = _spec("1", "positive_int", "DEM steps between equilibrium checks")
    max_relaxation_steps: int = _spec("1", "positive_int",
                                      "no equilibrium at the held load within this many steps = failure")
    max_relaxation_crossings: float = _spec("1", "nonnegative",
                                            "relaxation budget in elastic wave crossings of the specimen's height, "
                                            "where longer than max_relaxation_steps; 0 = steps alone")
    collapse_strain_increment: float = _spec("1", "nonnegative",
                                             "collapse = failure: the servo closes the platens at its speed limit "
                                             "on every DEM step while the axial strain grows by more than this; "
                                             "0 = criterion off")
    collapse_stress_ratio: float = _spec("1", "unit_interval",
                                         "collapse also needs the held stress below this fraction of the target "
                                         "(a cascade the specimen arrests keeps it higher); 1 = saturation alone")
    failure_strain: float = _spec("1", "positive", "axial strain at which a run counts as failed (safety cap)")
    relaxation_damping: float = _spec("1", "fraction_below_one", "Cundall damping of the creep phase (after the "
                                      "ramp: every relaxation); 0 = numerics.damping, as in the ramp")
    record_period: int = _spec("1", "positive_int", "paper clock: law applications between history rows")


@dataclass(frozen=True, kw_only=True)
class BrazilianParams:
    """Strain-controlled Brazilian disc test: diametral compression between two rigid loading jaws
    (ISRM 1978 suggested method); tensile strength sigma_t = 2 P / (pi D t) at the peak load P."""
    diameter: float = _spec("m", "positive", "disc diameter D")
    loading_arc_deg: float = _spec("deg", "angle", "full angle 2 alpha of each jaw's arc about the loaded diameter: "
                                   "the cells whose rim overlaps it move with the jaw")
    strain_rate: float = _spec("1/s", "positive", "jaw closing speed / D (DEM time)")
    stop_load_ratio: float = _spec("1", "unit_interval_open", "stop when the load falls below this x peak "
                                   "(with bonds broken since the peak)")
    stop_min_strain: float = _spec("1", "nonnegative", "the post-peak stop applies only once the diametral strain "
                                   "has passed this (a drop in the start transient is not the split)")
    max_strain: float = _spec("1", "positive", "stop at this diametral strain (jaw closure / D)")
    record_strain_increment: float = _spec("1", "positive", "diametral strain between history rows")
    platen_lateral: str = _spec("", "choice", "jaw cells fixed (rough, hold the disc) or free (smooth) "
                                "across the loaded diameter", ("fixed", "free"))


@dataclass(frozen=True, kw_only=True)
class ConfinementParams:
    """Confined (biaxial) loading: a constant confining stress on the side walls of the plane specimen,
    sigma_3, for the compression and creep tests; 0 is uniaxial loading (paper section 3.1)."""
    stress: float = _spec("Pa", "nonnegative", "confining stress sigma_3 held on the side walls; 0 = uniaxial")


@dataclass(frozen=True, kw_only=True)
class CalibrationParams:
    """Scale factors that map the paper's UDEC values (Tables 1 and 2) onto this YADE packing, and the
    levers on the contacts a calibration to more lab properties may turn.

    ``strength_scale`` and ``stiffness_scale``: one factor for all mineral pairs, so the ratios of Table
    2 stay as printed.  The levers (:func:`calibrated_contact`, :mod:`grainfrac_yade.contact_strength`)
    change one ratio each: k_s / k_n, J^T / J^C, inter- over intra-mineral strength, and the scatter
    of strength between faces; at their defaults (1, 1, 1, 0) they change nothing.
    """
    strength_scale: float = _spec("1", "positive", "multiplies J^T and J^C of every contact")
    stiffness_scale: float = _spec("1", "positive", "multiplies the series normal and shear stiffness of every bond")
    reference_ucs: float = _spec("Pa", "positive", "UCS a driving-stress ratio refers to: calibrated mean")
    shear_stiffness_ratio_scale: float = _spec("1", "positive", "multiplies every pair's k_s / k_n "
                                               "(contacts.\"a/b\".shear_stiffness_ratio, which stays per pair): the "
                                               "contact shear stiffness k_s, before the grain's compliance in series; "
                                               "one knob for the k_s / k_n of all pairs; 1 = as the pairs give it")
    tensile_cohesion_ratio_scale: float = _spec("1", "positive", "multiplies J^T of every contact, J^C kept: each "
                                                "pair's J^T / J^C times this, Table 2's differences between minerals "
                                                "kept; 1 = as the pairs give it")
    inter_mineral_strength_ratio: float = _spec("1", "positive", "multiplies J^T and J^C of the contacts between "
                                                "cells of different minerals (after the arithmetic-average rule, or "
                                                "as a file gives the pair): their strength over that rule's; 1 = the "
                                                "paper's rule")
    strength_weibull_modulus: float = _spec("1", "nonnegative", "Weibull modulus m of a per-face multiplier of J^T "
                                            "and J^C (unit mean, CV = sqrt(Gamma(1+2/m)/Gamma(1+1/m)^2 - 1); one "
                                            "draw per Voronoi face, seeded by the specimen's seed on a stream of its "
                                            "own: grainfrac_yade.contact_strength); 0 = no scatter, else >= 1 (CV <= 1)")


@dataclass(frozen=True, kw_only=True)
class Parameters:
    """A complete, validated parameter set."""
    specimen: SpecimenParams
    composition: Mapping[str, float]
    grains: Mapping[str, GrainParams]
    contacts: Mapping[tuple, ContactParams]
    resolution: ResolutionParams
    numerics: NumericsParams
    stress_corrosion: StressCorrosionParams
    ucs: UcsParams
    creep: CreepParams
    brazilian: BrazilianParams
    confinement: ConfinementParams
    calibration: CalibrationParams
    sources: tuple = ()

    @property
    def minerals(self) -> tuple:
        """Mineral names in file order."""
        return tuple(self.composition)

    def contact(self, mineral_a: str, mineral_b: str) -> ContactParams:
        """Contact parameters of a mineral pair (order does not matter)."""
        return self.contacts[pair_key(mineral_a, mineral_b)]

    def to_dict(self) -> dict:
        """Plain nested dict (file layout, SI units) for JSON run records."""
        out = {}
        for f in dataclasses.fields(self):
            if f.name == "sources":
                continue
            value = getattr(self, f.name)
            if dataclasses.is_dataclass(value):
                out[f.name] = dataclasses.asdict(value)
            elif f.name == "composition":
                out[f.name] = dict(value)
            elif f.name == "grains":
                out[f.name] = {m: dataclasses.asdict(g) for m, g in value.items()}
            elif f.name == "contacts":
                out[f.name] = {"/".join(k): dataclasses.asdict(c) for k, c in value.items()}
        out["sources"] = list(self.sources)
        return out


SECTION_CLASSES = {
    "specimen": SpecimenParams,
    "resolution": ResolutionParams,
    "numerics": NumericsParams,
    "stress_corrosion": StressCorrosionParams,
    "ucs": UcsParams,
    "creep": CreepParams,
    "brazilian": BrazilianParams,
    "confinement": ConfinementParams,
    "calibration": CalibrationParams,
}


def pair_key(mineral_a: str, mineral_b: str) -> tuple:
    """Canonical key of a mineral pair: the two names sorted."""
    return tuple(sorted((mineral_a, mineral_b)))


def average_contact(a: ContactParams, b: ContactParams) -> ContactParams:
    """Contact of a mixed pair: arithmetic average of each parameter (paper section 3.1)."""
    return ContactParams(**{f.name: 0.5 * (getattr(a, f.name) + getattr(b, f.name))
                            for f in dataclasses.fields(ContactParams)})


def calibrated_contact(contact: ContactParams, mixed: bool, calibration: CalibrationParams) -> ContactParams:
    """A pair's contact with the pair-wise levers of ``calibration``: k_s / k_n x
    ``shear_stiffness_ratio_scale``; J^T x ``tensile_cohesion_ratio_scale``; for a ``mixed`` pair (two
    different minerals) J^T and J^C x ``inter_mineral_strength_ratio`` too.  Every factor 1: the same
    values, bit for bit (x * 1.0 == x)."""
    inter = calibration.inter_mineral_strength_ratio if mixed else 1.0
    return dataclasses.replace(
        contact, shear_stiffness_ratio=contact.shear_stiffness_ratio * calibration.shear_stiffness_ratio_scale,
        tensile_strength=contact.tensile_strength * calibration.tensile_cohesion_ratio_scale * inter,
        cohesion=contact.cohesion * inter)


def field_spec(dotted: str) -> Mapping:
    """Unit, check, meaning and choices of schema key ``section.key`` (ParameterError if there is none)."""
    section, _, key = dotted.partition(".")
    cls = SECTION_CLASSES.get(section)
    fields = {f.name: f for f in dataclasses.fields(cls)} if cls else {}
    if key not in fields:
        raise ParameterError("parameter file", dotted, "no such parameter", "use a key of the schema (grainfrac_yade/params/schema.py)")
    return fields[key].metadata


__all__ = ["PARAMS_DIR", "DEFAULT_FILES", "FRACTION_SUM_TOLERANCE", "NEAREST_KEY_CUTOFF", "SpecimenParams", "GrainParams", "ContactParams", "ResolutionParams", "NumericsParams", "StressCorrosionParams", "unbalanced_threshold", "UcsParams", "CreepParams", "BrazilianParams", "ConfinementParams", "CalibrationParams", "Parameters", "SECTION_CLASSES", "pair_key", "average_contact", "calibrated_contact", "field_spec", "_check_value", "nearest_key", "RETIRED_VALUES"]
