"""Assembly of the full system mass and stiffness matrices from member data.

    M = Σ_i β_iᵀ M_e,i β_i,    K = Σ_i β_iᵀ K_e,i β_i      (Gnilka eqs. 3.6, 3.7)

β_i is built from each member's signed coordinate map (see
:class:`vtool.solvers.spec.MemberSpec`): row r of β_i has ±1 in the column of
the system coordinate that element coordinate r follows, or is zero for a
grounded end.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vtool.solvers.elements import bar_matrices, beam_matrices
from vtool.solvers.spec import BAR, MechanismSpec, MemberSpec


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
            density = member.specific_weight / gravity  # type: ignore[operator]
        mass = density * area * member.length  # type: ignore[operator]
    modulus = member.modulus or 0.0
    if member.element == BAR:
        axial = member.stiffness if member.stiffness is not None else modulus * area / member.length  # type: ignore[operator]
        bending = 0.0
    else:
        axial = 0.0
        bending = modulus * inertia  # type: ignore[operator]
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
        K_e, M_e = element_matrices(member_properties(member, spec.gravity))
        beta = beta_matrix(member.coordinates, n)
        M += beta.T @ M_e @ beta
        K += beta.T @ K_e @ beta
    return 0.5 * (M + M.T), 0.5 * (K + K.T)
