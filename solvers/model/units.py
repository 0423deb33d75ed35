"""Unit systems a valve-train preset can declare: :mod:`vtool.units`, the one units module.

Kept so ``vtool.solvers.model.units.UNIT_SYSTEMS`` and ``UnitSystem`` still import;
they are the same objects as in :mod:`vtool.units`.
"""

from __future__ import annotations

from vtool.units import UNIT_SYSTEMS, UnitSystem

__all__ = ["UNIT_SYSTEMS", "UnitSystem"]
