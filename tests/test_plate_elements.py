"""Plate elements: Hermite bases, exact matrices, constant-curvature patch test.

References: the defining conditions of the Hermite bases; the strain energy
of a constant-curvature field, U = ½ D A (κxx² + κyy² + 2ν κxx κyy + 2(1−ν) κxy²)
(Timoshenko & Woinowsky-Krieger, ch. 1), which any convergent conforming
element must reproduce exactly.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vtool.assessments.plate.elements import (
    BFS16,
    CORNERS,
    DOF_ORDERS,
    MASON24,
    element_matrices,
    hermite_coefficients,
    hermite_values,
)

ELEMENTS = [BFS16, MASON24]


@pytest.mark.parametrize("order", [2, 3])
def test_hermite_basis_carries_one_derivative_at_one_end(order: int) -> None:
    c = hermite_coefficients(order)
    for end in range(2):
        for k in range(order):
            poly = np.polynomial.Polynomial(c[end, k])
            for other_end, xi in enumerate((0.0, 1.0)):
                for j in range(order):
                    value = poly.deriv(j)(xi) if j else poly(xi)
                    expected = 1.0 if (other_end, j) == (end, k) else 0.0
                    assert value == pytest.approx(expected, abs=1e-12)


def _nodal_values(element, dx: float, dy: float, fn) -> np.ndarray:
    """Nodal unknowns of a field given as fn(x, y, p, q) = ∂^{p+q} w / ∂x^p ∂y^q."""
    out = []
    for cx, cy in CORNERS:
        for name in element.nodal_dofs:
            p, q = DOF_ORDERS[name]
            out.append(fn(cx * dx, cy * dy, p, q))
    return np.array(out)


def _quadratic(alpha: float, beta: float, gamma: float):
    """w = α x² + β x y + γ y² and its derivatives."""
    def fn(x: float, y: float, p: int, q: int) -> float:
        table = {
            (0, 0): alpha * x * x + beta * x * y + gamma * y * y,
            (1, 0): 2 * alpha * x + beta * y, (0, 1): beta * x + 2 * gamma * y,
            (1, 1): beta, (2, 0): 2 * alpha, (0, 2): 2 * gamma,
        }
        return table[(p, q)]
    return fn


@pytest.mark.parametrize("element", ELEMENTS, ids=lambda e: e.name)
@given(
    dx=st.floats(0.2, 20.0), dy=st.floats(0.2, 20.0), nu=st.floats(-0.9, 0.49),
    alpha=st.floats(-2, 2), beta=st.floats(-2, 2), gamma=st.floats(-2, 2),
)
@settings(max_examples=25, deadline=None)
def test_constant_curvature_patch(element, dx, dy, nu, alpha, beta, gamma) -> None:
    D = 3.7
    _, K, _ = element_matrices(element, dx, dy, rigidity=D, mass_per_area=1.0, poisson=nu)
    u = _nodal_values(element, dx, dy, _quadratic(alpha, beta, gamma))
    kxx, kyy, kxy = 2 * alpha, 2 * gamma, beta
    exact = D * dx * dy * (kxx**2 + kyy**2 + 2 * nu * kxx * kyy + 2 * (1 - nu) * kxy**2)
    # rounding: the form sums n² products u_i K_ij u_j (n = 24 at most) whose sizes grow with the element's
    # aspect (nodal values like size², stiffnesses like size⁻²) while the energy does not: its error is
    # bounded by n ε Σ|u_i K_ij u_j|. That is 1e-12 of the energy on a square element and 1e-5 of it on
    # one of aspect 80 (where a fixed 1e-7 failed: 1.6e-7, dx = 17.5, dy = 0.21875, all rounding). Below the
    # normal range that bound underflows and each of the form's 2n² operations, and the few of ``exact``, may
    # round by up to a subnormal step (CI: gamma = 1.6e-161 gave 3.844e-321 against 3.84e-321)
    scale = np.abs(u) @ np.abs(K) @ np.abs(u)
    subnormal = 2 * (len(u) ** 2 + 8) * np.finfo(float).smallest_subnormal
    assert u @ K @ u == pytest.approx(exact, rel=1e-12, abs=len(u) * np.finfo(float).eps * scale + subnormal)


@pytest.mark.parametrize("element", ELEMENTS, ids=lambda e: e.name)
@given(dx=st.floats(0.2, 20.0), dy=st.floats(0.2, 20.0), nu=st.floats(-0.9, 0.49))
@settings(max_examples=20, deadline=None)
def test_element_matrices_symmetric_semidefinite_with_three_rigid_modes(element, dx, dy, nu) -> None:
    M, K, f = element_matrices(element, dx, dy, rigidity=1.0, mass_per_area=2.0, poisson=nu)
    assert np.allclose(K, K.T, atol=1e-12 * np.abs(K).max())
    assert np.allclose(M, M.T, atol=1e-12 * np.abs(M).max())
    lam_k = np.linalg.eigvalsh(K / np.abs(K).max())
    assert np.sum(lam_k < 1e-9) == 3  # w = 1, x, y: no strain
    assert lam_k.min() > -1e-9
    assert np.linalg.eigvalsh(M).min() > 0.0
    rigid = _nodal_values(element, dx, dy, lambda x, y, p, q: 1.0 if (p, q) == (0, 0) else 0.0)
    assert rigid @ M @ rigid == pytest.approx(2.0 * dx * dy, rel=1e-12)  # total mass ρh A
    assert rigid @ f == pytest.approx(dx * dy, rel=1e-12)  # load of a unit pressure


def test_bicubic_field_is_exact_in_bfs16_mass() -> None:
    """w = x³ y³ lies in the bicubic space: uᵀ M u is its exact ∫ w² dA."""
    dx, dy = 1.3, 0.7

    def fn(x, y, p, q):
        dpx = math.perm(3, p) * x ** (3 - p)
        dqy = math.perm(3, q) * y ** (3 - q)
        return dpx * dqy

    M, _, _ = element_matrices(BFS16, dx, dy, rigidity=1.0, mass_per_area=1.0, poisson=0.3)
    u = _nodal_values(BFS16, dx, dy, fn)
    assert u @ M @ u == pytest.approx(dx**7 / 7 * dy**7 / 7, rel=1e-12)


def test_quintic_basis_scaling_to_physical_derivatives() -> None:
    """The slope basis at ξ = 0 has physical slope 1 (not 1/L)."""
    L = 2.5
    h = 1e-6
    v = hermite_values(3, np.array([0.0, h]), 0, L)
    assert (v[0, 1, 1] - v[0, 1, 0]) / (h * L) == pytest.approx(1.0, rel=1e-4)
    d2 = hermite_values(3, np.array([0.0]), 2, L)
    assert d2[0, 2, 0] == pytest.approx(1.0)
