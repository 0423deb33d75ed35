"""Assembly of the full system mass and stiffness matrices from member data.

    M = Σ_i β_iᵀ M_e,i β_i,    K = Σ_i β_iᵀ K_e,i β_i      (Gnilka eqs. 3.6, 3.7)

β_i is built from each member's signed coordinate map (see
:class:`vtool.solvers.model.spec.MemberSpec`): row r of β_i has ±1 in the column of
the system coordinate that element coordinate r follows, or is zero for a
grounded end.

A member with ``elements = n > 1`` is n equal elements in a chain (length,
explicit stiffness x n and explicit mass / n per element), joined at n - 1
internal nodes that :func:`split_members` numbers after the preset's elastic
coordinates (bars: one translation per node; beams: a deflection and a
rotation). The prescribed coordinates (cam, seat) move up by the number of new
coordinates, so that elastic coordinates stay 1..n as every back end assumes.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, replace

import numpy as np

from vtool.solvers.model.elements import bar_matrices, beam_matrices
from vtool.solvers.model.spec import BAR, CoordinateSpec, MechanismSpec, MemberSpec


@dataclass(frozen=True)
class MemberProperties:
    """Section and material of one member, resolved to the numbers the element needs."""

    name: str
    element: str
    length: float
    axial_stiffness: float  # EA/L or the explicit stiffness (bars)
    bending_stiffness: float  # EI (beams)
    mass: float  # total member mass


def member_properties(member: MemberSpec, gravity: float) -> MemberProperties:
    """Resolve a member's section, stiffness and mass (explicit values win)."""
    area = member.area
    inertia = member.inertia
    if member.diameter is not None:
        area = math.pi * member.diameter**2 / 4.0 if area is None else area
        inertia = math.pi * member.diameter**4 / 64.0 if inertia is None else inertia
    if member.mass is not None:
        mass = member.mass
    else:
        density = member.density
        if density is None:
            density = member.specific_weight / gravity  # type: ignore[operator]  # the loader gives one of each pair (area/diameter, ...)
        mass = density * area * member.length  # type: ignore[operator]  # the loader gives one of each pair (area/diameter, ...)
    modulus = member.modulus or 0.0
    if member.element == BAR:
        axial = member.stiffness if member.stiffness is not None else modulus * area / member.length  # type: ignore[operator]  # the loader gives one of each pair (area/diameter, ...)
        bending = 0.0
    else:
        axial = 0.0
        bending = modulus * inertia  # type: ignore[operator]  # the loader gives one of each pair (area/diameter, ...)
    return MemberProperties(member.name, member.element, member.length, axial, bending, mass)


def element_matrices(props: MemberProperties) -> tuple[np.ndarray, np.ndarray]:
    """(K_e, M_e) of one member in thesis element-coordinate order."""
    if props.element == BAR:
        return bar_matrices(props.axial_stiffness, props.mass)
    return beam_matrices(props.bending_stiffness, props.length, props.mass)


def beta_matrix(coordinate_map: tuple[int, ...], n_coordinates: int) -> np.ndarray:
    """β_i: element coordinates from system coordinates, u = β q (eq. 3.2)."""
    beta = np.zeros((len(coordinate_map), n_coordinates))
    for row, signed in enumerate(coordinate_map):
        if signed:
            beta[row, abs(signed) - 1] = math.copysign(1.0, signed)
    return beta


def assemble_full(spec: MechanismSpec) -> tuple[np.ndarray, np.ndarray]:
    """Full system (M, K) over the elastic coordinates q_1..q_n, all clearances open."""
    n = spec.n_coordinates
    M = np.zeros((n, n))
    K = np.zeros((n, n))
    for member in spec.members:
        for element in sub_elements(member):
            K_e, M_e = element_matrices(member_properties(element, spec.gravity))
            beta = beta_matrix(element.coordinates, n)
            M += beta.T @ M_e @ beta
            K += beta.T @ K_e @ beta
    return 0.5 * (M + M.T), 0.5 * (K + K.T)


def sub_elements(member: MemberSpec) -> list[MemberSpec]:
    """The member's n equal elements, end a to end b through its internal nodes."""
    n = member.elements
    if n == 1:
        return [member]
    c = member.coordinates
    if member.element == BAR:
        chain: list[tuple[int, ...]] = [(c[0],), *[(node,) for node in member.nodes], (c[1],)]
    else:
        pairs = list(zip(member.nodes[::2], member.nodes[1::2], strict=True))
        chain = [(c[0], c[2]), *pairs, (c[1], c[3])]
    result = []
    for k in range(n):
        a, b = chain[k], chain[k + 1]
        coords = (a[0], b[0]) if member.element == BAR else (a[0], b[0], a[1], b[1])
        result.append(replace(
            member, name=f"{member.name} element {k + 1}", length=member.length / n, coordinates=coords,
            stiffness=None if member.stiffness is None else member.stiffness * n,
            mass=None if member.mass is None else member.mass / n, elements=1, nodes=()))
    return result


def node_count(member: MemberSpec) -> int:
    """Internal coordinates a split member adds: (n - 1) per node DOF."""
    return (member.elements - 1) * (1 if member.element == BAR else 2)


def renumber_quantity(text: str, first: int, shift: int) -> str:
    """Shift the coordinate numbers >= ``first`` in a quantity ('q9', 'q1-q9'; 'F<i>' is kept)."""
    if text.startswith("F"):
        return text
    return re.sub(r"\d+", lambda m: str(int(m[0]) + shift if int(m[0]) >= first else int(m[0])), text)


def split_members(spec: MechanismSpec) -> MechanismSpec:
    """Number the internal nodes of members with ``elements > 1`` (see module doc).

    The spec comes in the preset's numbering (prescribed coordinates right
    after its elastic ones); nodes take the numbers n+1, n+2, ... and the cam,
    the seat, the clearances behind them and the run's quantities move up.
    """
    n = spec.n_coordinates
    added = sum(node_count(m) for m in spec.members)
    if added == 0:
        return spec
    coordinates = list(spec.coordinates)
    members = []
    for member in spec.members:
        nodes = []
        for k in range(1, member.elements):
            coordinates.append(CoordinateSpec(len(coordinates) + 1, f"{member.name} node {k}", "translation"))
            nodes.append(len(coordinates))
            if member.element != BAR:
                coordinates.append(
                    CoordinateSpec(len(coordinates) + 1, f"{member.name} node {k} rotation", "rotation"))
                nodes.append(len(coordinates))
        members.append(replace(member, nodes=tuple(nodes)))
    return _shift_prescribed(spec, n + 1, added, tuple(coordinates), tuple(members))


def unsplit_members(spec: MechanismSpec) -> MechanismSpec:
    """The inverse of :func:`split_members`: the spec in the preset's numbering."""
    removed = sum(len(m.nodes) for m in spec.members)
    if removed == 0:
        return spec
    n = spec.n_coordinates - removed
    members = tuple(replace(m, nodes=()) for m in spec.members)
    return _shift_prescribed(spec, n + removed + 1, -removed, spec.coordinates[:n], members)


def _shift_prescribed(spec: MechanismSpec, first: int, shift: int, coordinates: tuple[CoordinateSpec, ...],
                      members: tuple[MemberSpec, ...]) -> MechanismSpec:
    def moved(number: int) -> int:
        return number + shift if number >= first else number

    cam = replace(spec.cam, coordinate=moved(spec.cam.coordinate))
    seat = None if spec.seat is None else replace(spec.seat, coordinate=moved(spec.seat.coordinate))
    clearances = tuple(replace(c, behind=moved(c.behind)) for c in spec.clearances)
    quantities = tuple(renumber_quantity(q, first, shift) for q in spec.run.quantities)
    return replace(spec, coordinates=coordinates, members=members, cam=cam, seat=seat, clearances=clearances,
                   run=replace(spec.run, quantities=quantities))


SURGE_SHARE = 0.5


def kinetic_shares(spec: MechanismSpec, shapes: np.ndarray) -> dict[str, np.ndarray]:
    """Each member's share of every mode's kinetic energy, φ_eᵀ M_e φ_e / φᵀ M φ.

    ``shapes`` are mode shapes over the full coordinates (columns), e.g. T φ_L.
    """
    n = spec.n_coordinates
    total = np.zeros(shapes.shape[1])
    shares = {}
    for member in spec.members:
        energy = np.zeros(shapes.shape[1])
        for element in sub_elements(member):
            _, M_e = element_matrices(member_properties(element, spec.gravity))
            u = beta_matrix(element.coordinates, n) @ shapes
            energy += np.einsum("im,ij,jm->m", u, M_e, u)
        shares[member.name] = energy
        total += energy
    return {name: energy / np.where(total > 0, total, 1.0) for name, energy in shares.items()}


def surge_labels(spec: MechanismSpec, shapes: np.ndarray) -> list[str]:
    """'<member> surge' for modes carried mostly (> 50 % of kinetic energy) by a split member, else ''.

    A member of one element has no modes of its own; split into n it has n - 1
    (bars) internal ones: for the valve spring, its surge modes.
    """
    labels = [""] * shapes.shape[1]
    for name, share in kinetic_shares(spec, shapes).items():
        member = next(m for m in spec.members if m.name == name)
        if member.elements > 1:
            for mode in np.nonzero(share > SURGE_SHARE)[0]:
                labels[mode] = f"{name} surge"
    return labels
