"""Contact layers: the mechanism with a given set of internal clearances closed.

A closed internal clearance ties its two coordinates together (equal
displacement, velocity and acceleration), so the pair becomes one coordinate,
numbered as the lower of the two (the thesis ties q8 to q2 and keeps seven
coordinates). Pinned clearances are closed in every layer. External
clearances (cam, seat) do not change a layer: their prescribed coordinates are
partitioned out per configuration by the solver.

With T the n × m matrix that expands the m layer coordinates to the n full
ones (a column of ones on each tied pair),

    M_L = Tᵀ M T,   K_L = Tᵀ K T,   C_L = modal damping of (M_L, K_L)

Each layer has its own eigenproblem and its own damping (thesis: layer 1,
rocker open, 8 coordinates; layer 3, rocker in contact, 7 coordinates).
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

import numpy as np

from vtool.solvers.model.damping import Modes, modal_damping, mode_ratios, undamped_modes
from vtool.solvers.model.spec import ENABLED, INTERNAL, PINNED, MechanismSpec


@dataclass(frozen=True)
class Layer:
    """One contact layer: its coordinates, matrices and modes.

    ``kept`` lists the full-system coordinate numbers (1-based) that remain;
    ``T`` (n × m) expands layer coordinates to full ones: q = T q_L.
    """

    closed: frozenset[str]
    kept: tuple[int, ...]
    T: np.ndarray
    M: np.ndarray
    K: np.ndarray
    C: np.ndarray
    modes: Modes
    damping_ratios: np.ndarray

    @property
    def size(self) -> int:
        return len(self.kept)

    def label(self) -> str:
        return "closed: " + (", ".join(sorted(self.closed)) if self.closed else "none")


def tie_matrix(n: int, pairs: list[tuple[int, int]]) -> tuple[np.ndarray, tuple[int, ...]]:
    """T for tying coordinate pairs (1-based); each tied group keeps its lowest number."""
    parent = list(range(n + 1))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for a, b in pairs:
        ra, rb = root(a), root(b)
        if ra != rb:
            parent[max(ra, rb)] = min(ra, rb)
    kept = tuple(i for i in range(1, n + 1) if root(i) == i)
    column = {number: j for j, number in enumerate(kept)}
    T = np.zeros((n, len(kept)))
    for i in range(1, n + 1):
        T[i - 1, column[root(i)]] = 1.0
    return T, kept


def internal_layer_names(spec: MechanismSpec) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """(enabled, pinned) names of the rigid internal clearances: the ones that tie a pair.

    A compliant internal clearance never ties its pair: its spring joins the
    configuration's matrices instead (:mod:`vtool.solvers.model.contact`)."""
    enabled = tuple(c.name for c in spec.clearances if c.ties and c.state == ENABLED)
    pinned = tuple(c.name for c in spec.clearances if c.ties and c.state == PINNED)
    return enabled, pinned


def possible_layers(spec: MechanismSpec) -> list[frozenset[str]]:
    """Every set of closed internal clearances the run can meet (2^k for k enabled)."""
    enabled, pinned = internal_layer_names(spec)
    layers = []
    for r in range(len(enabled) + 1):
        for subset in combinations(enabled, r):
            layers.append(frozenset(subset) | frozenset(pinned))
    return layers


def build_layer(spec: MechanismSpec, M: np.ndarray, K: np.ndarray, closed: frozenset[str]) -> Layer:
    """Reduce the full (M, K) to one layer and compute its modes and modal damping.

    Every internal clearance named in ``closed`` ties its pair (the caller
    passes only the rigid ones, except for :meth:`Mechanism.tied_layer`)."""
    pairs = [(c.ahead, c.behind) for c in spec.clearances if c.kind == INTERNAL and c.name in closed]
    T, kept = tie_matrix(spec.n_coordinates, pairs)
    M_L = T.T @ M @ T
    K_L = T.T @ K @ T
    modes = undamped_modes(M_L, K_L)
    damping = spec.damping.for_layer(frozenset(closed))
    overrides = damping.mode_ratios
    if overrides and any(m.nodes for m in spec.members):
        overrides = _follow_split_modes(spec, closed, kept, modes, overrides)
    ratios = mode_ratios(len(kept), damping.default_ratio, overrides)
    C_L = modal_damping(M_L, modes, ratios, spec.damping.factor)
    return Layer(frozenset(closed), kept, T, M_L, K_L, C_L, modes, ratios)


def _follow_split_modes(spec: MechanismSpec, closed: frozenset[str], kept: tuple[int, ...], modes,
                        overrides: tuple[tuple[int, float], ...]) -> tuple[tuple[int, float], ...]:
    """Per-mode damping overrides number the modes of the preset's one-element model.

    In a model with split members (more, and new low, modes) each override
    goes to the mode whose shape over the preset's coordinates best matches
    (largest MAC) the one-element model's mode of that number.
    """
    from dataclasses import replace

    from vtool.solvers.model.assembly import assemble_full, unsplit_members

    plain = unsplit_members(spec)
    plain = replace(plain, members=tuple(replace(m, elements=1) for m in plain.members))
    M, K = assemble_full(plain)
    reference = build_layer(plain, M, K, closed)
    rows = [j for j, number in enumerate(kept) if number <= plain.n_coordinates]
    split_shapes = modes.shapes[rows]
    moved = []
    for number, ratio in overrides:
        if not 1 <= number <= reference.size:
            continue
        phi = reference.modes.shapes[:, number - 1]
        mac = (phi @ split_shapes) ** 2 / ((phi @ phi) * np.einsum("ij,ij->j", split_shapes, split_shapes))
        moved.append((int(np.argmax(mac)) + 1, ratio))
    return tuple(moved)
