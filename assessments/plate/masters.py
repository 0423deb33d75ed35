"""Master sets: which nodal unknowns a reduced model keeps.

Three ways to name them:

* a named set, as in the thesis' cases (:data:`NAMED_SETS`);
* explicit labels ``"w@2,2"``: unknown ``w`` at node (i=2, j=2), nodes
  counted from the corner (0, 0) along x (i) and y (j);
* automatic (Henshell–Ong): a number of masters, chosen by
  :func:`vtool.assessments.plate.reduction.henshell_ong_masters`.

"Interior" nodes are those off the supported edges. The "five points" sets
need a mesh divisible by 4 in both directions: the centre plus either the
four interior nodes half-way to the mid-sides (``plus``: the thesis' choice
that eliminates the least flexible nodes, nearest the corners, first) or
the four half-way to the corners (``cross``: keeps those stiff nodes).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from vtool.assessments.plate.assembly import Mesh


class MasterSetError(ValueError):
    """A master set names a constrained or non-existent DOF, or does not fit the mesh."""


def _interior(mesh: Mesh) -> list[tuple[int, int]]:
    return [(i, j) for j in range(1, mesh.ny) for i in range(1, mesh.nx)]


def _centre(mesh: Mesh) -> tuple[int, int]:
    if mesh.nx % 2 or mesh.ny % 2:
        raise MasterSetError(f"the centre is a node only on an even mesh (got {mesh.nx} x {mesh.ny})")
    return mesh.nx // 2, mesh.ny // 2


def _five(mesh: Mesh, pattern: str) -> list[tuple[int, int]]:
    if mesh.nx % 4 or mesh.ny % 4:
        raise MasterSetError(f"five-point sets need a mesh divisible by 4 (got {mesh.nx} x {mesh.ny})")
    ci, cj = mesh.nx // 2, mesh.ny // 2
    qi, qj = mesh.nx // 4, mesh.ny // 4
    if pattern == "plus":
        return [(ci, cj - qj), (ci - qi, cj), (ci, cj), (ci + qi, cj), (ci, cj + qj)]
    return [(ci - qi, cj - qj), (ci + qi, cj - qj), (ci, cj), (ci - qi, cj + qj), (ci + qi, cj + qj)]


@dataclass(frozen=True)
class NamedSet:
    description: str
    nodes: Callable[[Mesh], list[tuple[int, int]]] | None  # None: every free DOF
    unknowns: tuple[str, ...] | None  # None: every nodal unknown of the element


NAMED_SETS: dict[str, NamedSet] = {
    "all": NamedSet("all DOF (no reduction)", None, None),
    "interior-all": NamedSet("every nodal unknown at the interior nodes", _interior, None),
    "interior-w-slopes-twist": NamedSet("w, wx, wy, wxy at the interior nodes", _interior, ("w", "wx", "wy", "wxy")),
    "interior-w-slopes": NamedSet("w, wx, wy at the interior nodes", _interior, ("w", "wx", "wy")),
    "interior-w": NamedSet("w at the interior nodes", _interior, ("w",)),
    "five-plus-all": NamedSet("every nodal unknown at five interior points (+)", lambda m: _five(m, "plus"), None),
    "five-plus-w-slopes": NamedSet("w, wx, wy at five interior points (+)", lambda m: _five(m, "plus"), ("w", "wx", "wy")),
    "five-plus-w": NamedSet("w at five interior points (+, corners eliminated first)", lambda m: _five(m, "plus"), ("w",)),
    "five-cross-w": NamedSet("w at five interior points (x, nearest the corners)", lambda m: _five(m, "cross"), ("w",)),
    "centre-w": NamedSet("w at the centre node alone", lambda m: [_centre(m)], ("w",)),
}


def named_set(mesh: Mesh, name: str, free: np.ndarray) -> np.ndarray:
    """Positions (into ``free``) of the masters of a named set."""
    if name not in NAMED_SETS:
        raise MasterSetError(f"unknown master set {name!r} (known: {', '.join(NAMED_SETS)})")
    spec = NAMED_SETS[name]
    if spec.nodes is None:
        return np.arange(free.size)
    unknowns = spec.unknowns or mesh.element.nodal_dofs
    missing = [u for u in unknowns if u not in mesh.element.nodal_dofs]
    if missing:
        raise MasterSetError(
            f"set {name!r} needs {', '.join(missing)}, which the {mesh.element.name} element lacks"
        )
    labels = [f"{u}@{i},{j}" for (i, j) in spec.nodes(mesh) for u in unknowns]
    return labelled_set(mesh, labels, free)


def parse_label(mesh: Mesh, label: str) -> int:
    """Global DOF index of ``"w@i,j"``; MasterSetError if malformed or outside the mesh."""
    try:
        name, node = label.split("@")
        i_text, j_text = node.split(",")
        i, j = int(i_text), int(j_text)
    except ValueError:
        raise MasterSetError(f"{label!r} is not of the form UNKNOWN@I,J (e.g. w@2,2)") from None
    if name not in mesh.element.nodal_dofs:
        raise MasterSetError(
            f"{label!r}: {name!r} is not an unknown of {mesh.element.name} "
            f"({', '.join(mesh.element.nodal_dofs)})"
        )
    if not (0 <= i <= mesh.nx and 0 <= j <= mesh.ny):
        raise MasterSetError(f"{label!r}: node ({i}, {j}) is outside the {mesh.nx} x {mesh.ny} mesh")
    return mesh.dof(i, j, name)


def labelled_set(mesh: Mesh, labels: list[str] | tuple[str, ...], free: np.ndarray) -> np.ndarray:
    """Positions (into ``free``) of labelled masters; constrained or repeated labels are errors."""
    if not labels:
        raise MasterSetError("a master set needs at least one DOF")
    position = {int(g): k for k, g in enumerate(free)}
    out = []
    for label in labels:
        g = parse_label(mesh, label)
        if g not in position:
            raise MasterSetError(f"{label!r} is fixed by the simply supported edge")
        out.append(position[g])
    if len(set(out)) != len(out):
        raise MasterSetError("a master set names the same DOF twice")
    return np.array(sorted(out), dtype=int)
