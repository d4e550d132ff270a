"""CLI commands, one module each; :func:`register_all` adds the ones beyond ``specimen``."""
import importlib


def register_all(subparsers, common):
    """Add later commands (ucs, creep, analyze, demo) to the CLI as they exist."""
    for name in ("ucs", "calibrate", "calibrate_beta1", "calibrate_lifetimes", "analyze_ucs", "creep", "analyze", "demo",
                 "elastic", "bench", "accuracy_cost",
                 "submit", "status", "brazilian", "batch"):
        try:
            module = importlib.import_module(f"{__name__}.{name}")
        except ModuleNotFoundError as exc:
            if exc.name == f"{__name__}.{name}":
                continue
            raise
        module.register(subparsers, common)
