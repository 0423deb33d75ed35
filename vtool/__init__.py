"""vtool: elastic valve-train dynamics with clearances, sonic-boom and condensed-plate checks.

The installed package maps the repository folders into one namespace:
``vtool.app`` (CLI and TUI), ``vtool.presets`` (TOML presets and their loaders),
``vtool.assessments`` (sonic boom, plate condensation) and ``vtool.solvers``
(valve-train model and back ends). Dependencies point one way:
app -> presets -> assessments -> solvers.

The Python API (:mod:`vtool.api`, docs/api.md) is reachable from here:
``vtool.load``, ``vtool.preset_names``, ``vtool.Model``, ``vtool.Result`` and ``vtool.SweepResult`` are looked up on first use by the module
``__getattr__`` below (PEP 562), so ``import vtool`` and ``import vtool.errors``
load none of the numerical stack; ``import vtool.api`` loads it explicitly.
"""

from __future__ import annotations

from typing import Any

__version__ = "0.1.0"

#: Names of :mod:`vtool.api` offered as ``vtool.NAME`` (resolved lazily, see the module doc).
API = ("load", "preset_names", "Model", "Result", "SweepResult")


def __getattr__(name: str) -> Any:
    if name in API:
        import importlib

        return getattr(importlib.import_module("vtool.api"), name)
    raise AttributeError(f"module 'vtool' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted([*globals(), *API])
