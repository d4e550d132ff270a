"""A static scene's relaxation strategy (engines/static/strategy.py): the hybrid engine is the static engine with
its strategy of dynamic stints, which reaches the scene only through the scene's public hooks; the post-peak rule
of a relaxation with the platens held is the test protocol's, given to the scene (no YADE)."""
import ast
from pathlib import Path

from import_cycles import graph

from grainfrac_yade.engines import Scene
from grainfrac_yade.engines.registry import engine
from grainfrac_yade.engines.static.inertial import FixedPlatens
from grainfrac_yade.engines.static.scene import StaticScene
from grainfrac_yade.engines.static.strategy import RelaxationHooks, SceneRelaxation
from grainfrac_yade.geometry.specimen import build_specimen
from grainfrac_yade.params import load_parameters

STINTS = Path(__file__).resolve().parents[1] / "grainfrac_yade" / "engines" / "hybrid" / "stints.py"
TINY = ["specimen.width=3e-3", "specimen.height=6e-3"]
#: What a strategy may read of a static scene beside its hooks and the scene interface: the core state it reads
#: closure and stress off, the held stress and the held load's failure.
SCENE_READS = {"state", "hold_target", "hold_failure"}


def _public(cls) -> set:
    return {n for c in cls.__mro__ for n in vars(c) if not n.startswith("_")}


def test_the_hybrid_strategy_uses_only_the_scene_s_public_hooks():
    """Every attribute the stints read or call on the scene (the name ``scene`` in stints.py) is a hook of
    :class:`RelaxationHooks`, a name of the scene interface or :data:`SCENE_READS`: none private, not its path,
    network or bond numbering."""
    allowed = _public(RelaxationHooks) | set(Scene.__annotations__) | _public(Scene) | SCENE_READS
    used = {node.attr for node in ast.walk(ast.parse(STINTS.read_text()))
            if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id == "scene"}
    assert used, "the stints read nothing of the scene: the check would pass on any code"
    assert used - allowed == set()
    assert {"adopt", "take_relaxed_state", "take_breaks", "take_lost_load", "add_steps"} <= used


def test_the_hybrid_is_the_static_scene_with_its_strategy():
    """The registry's hybrid builds a :class:`StaticScene` (not a subclass) whose strategy is the stints'; the
    static engine's is the plain one; the stints' module imports no engine module but the static engine's strategy
    interface and its cascade's hand-over signal, and only the hybrid's engine module looks a dynamic engine up."""
    p = load_parameters(overrides=[*TINY, "numerics.engine=hybrid"])
    specimen = build_specimen(p, 1)
    hybrid = engine("hybrid").build_scene(specimen, p)
    assert type(hybrid) is StaticScene and type(hybrid.strategy).__name__ == "DynamicStints"
    assert hybrid.engine_name == "hybrid" and hybrid.path.max_cascade == (p.numerics.handover_cascade_bonds or None)
    static = engine("static").build_scene(specimen, load_parameters(overrides=TINY))
    assert type(static.strategy) is SceneRelaxation and static.engine_name == "static"
    g = {k.removeprefix("grainfrac_yade."): {t.removeprefix("grainfrac_yade.") for t in v} for k, v in graph().items()}
    engines_used = {t for t in g["engines.hybrid.stints"] if t.startswith("engines") and
                    not t.startswith("engines.hybrid")}
    # (the static package itself: importing its sub-module runs its __init__)
    assert engines_used == {"engines.static", "engines.static.strategy", "engines.static.cascade"}
    assert {m for m, targets in g.items() if "engines.dynamic" in targets} <= {"engines.hybrid.engine",
                                                                                "engines.registry"}


def test_the_post_peak_rule_is_the_protocol_s():
    """A static scene has no post-peak rule of its own (a relaxation with the platens held never loses the load);
    the UCS test gives it ``ucs.stop_stress_ratio``, which its path keeps through a confinement's rebuild."""
    from grainfrac_yade.protocols.ucs import UcsRun
    p = load_parameters(overrides=[*TINY, "numerics.engine=static", "ucs.stop_stress_ratio=0.6"])
    specimen = build_specimen(p, 1)
    bare = engine("static").build_scene(specimen, p)
    assert bare.load_loss_ratio is None and bare.path.load_loss_ratio is None
    assert not FixedPlatens(None).lost(-1e300) and FixedPlatens(1.0).lost(0.5)
    run = UcsRun(specimen, p)
    assert run.scene.load_loss_ratio == 0.6 and run.scene.path.load_loss_ratio == 0.6
    run.scene.confine(1e6)
    assert run.scene.path.load_loss_ratio == 0.6


def test_a_confined_hybrid_scene_keeps_its_hand_over_size():
    """Confinement rebuilds the static path; the hybrid's hand-over size (``numerics.handover_cascade_bonds``)
    stays set on the rebuilt path (it was dropped once, so that a confined hybrid run never handed a large
    cascade to YADE)."""
    p = load_parameters(overrides=[*TINY, "numerics.engine=hybrid", "numerics.handover_cascade_bonds=2"])
    scene = engine("hybrid").build_scene(build_specimen(p, 1), p)
    assert scene.path.max_cascade == 2
    scene.confine(10e6)
    assert scene.path.max_cascade == 2
