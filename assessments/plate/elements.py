"""Conforming rectangular plate-bending elements built from 1-D Hermite bases.

Two elements, both products of 1-D Hermite polynomials in x and y:

``bfs16``
    Bogner–Fox–Schmit rectangle: nodal ``w, w_x, w_y, w_xy`` (4 per corner,
    16 per element); bicubic Hermite, ``N = H^3_{ip}(x) H^3_{jq}(y)``.
``mason24``
    The 24-DOF rectangle of the thesis (its reference 52, Mason): nodal
    ``w, w_x, w_y, w_xy, w_xx, w_yy`` (6 per corner). The shape functions are
    products of 1-D *quintic* Hermite polynomials (value, slope and curvature
    at each end), ``N = H^5_{ip}(x) H^5_{jq}(y)`` for the six derivative pairs
    (p, q) in {(0,0), (1,0), (0,1), (1,1), (2,0), (0,2)}; the three cross
    terms (2,1), (1,2), (2,2) of the full 36-term product are left out. Along
    an edge y = const, w and w_y then depend only on the two edge nodes, so the
    element is conforming (C¹ across element boundaries).

Element matrices are exact (Gauss–Legendre with enough points for the
highest polynomial degree)::

    M_e = ρh ∫∫ N Nᵀ dA
    K_e = D ∫∫ Bᵀ C B dA,  B = [N_xx; N_yy; 2 N_xy],
                            C = [[1, ν, 0], [ν, 1, 0], [0, 0, (1-ν)/2]]
    f_e = ∫∫ N dA          (consistent load of a unit uniform pressure)

with D = E h³ / (12 (1 - ν²)). Nodal unknowns are physical derivatives
(w_x, not the derivative in the element's unit coordinate), so assembled
elements of different sizes share nodal values directly.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cache, lru_cache

import numpy as np

#: Name of each nodal unknown and its derivative orders (in x, in y).
DOF_ORDERS: dict[str, tuple[int, int]] = {
    "w": (0, 0),
    "wx": (1, 0),
    "wy": (0, 1),
    "wxy": (1, 1),
    "wxx": (2, 0),
    "wyy": (0, 2),
}


@dataclass(frozen=True)
class ElementType:
    """A rectangular element family: its name, nodal unknowns and 1-D Hermite order.

    ``hermite_order`` r means each 1-D basis carries derivatives 0..r-1 at each
    end (r = 2: cubic, r = 3: quintic).
    """

    name: str
    nodal_dofs: tuple[str, ...]
    hermite_order: int
    title: str

    @property
    def dofs_per_node(self) -> int:
        return len(self.nodal_dofs)

    @property
    def dofs_per_element(self) -> int:
        return 4 * len(self.nodal_dofs)


BFS16 = ElementType("bfs16", ("w", "wx", "wy", "wxy"), 2, "16-DOF conforming rectangle (bicubic Hermite)")
MASON24 = ElementType(
    "mason24", ("w", "wx", "wy", "wxy", "wxx", "wyy"), 3,
    "24-DOF rectangle (quintic Hermite products, w..wyy)",
)
ELEMENTS: dict[str, ElementType] = {e.name: e for e in (BFS16, MASON24)}

#: Corner order of an element: (end in x, end in y), counter-clockwise from (0, 0).
CORNERS: tuple[tuple[int, int], ...] = ((0, 0), (1, 0), (1, 1), (0, 1))


@cache
def hermite_coefficients(order: int) -> np.ndarray:
    """Power-series coefficients of the 1-D Hermite basis on ξ ∈ [0, 1].

    Returns ``c`` of shape (2, order, 2*order): ``c[end, k]`` are the
    coefficients (ascending powers of ξ) of the polynomial whose k-th
    ξ-derivative is 1 at ``end`` (0 → ξ = 0, 1 → ξ = 1) and whose other
    derivatives 0..order-1 at both ends vanish.
    """
    degree = 2 * order
    rows = []
    for end in (0.0, 1.0):
        for k in range(order):
            row = np.zeros(degree)
            for p in range(k, degree):
                falling = math.perm(p, k)  # d^k/dξ^k ξ^p = p!/(p-k)! ξ^(p-k)
                row[p] = falling * (end ** (p - k) if p > k else 1.0)
            rows.append(row)
    V = np.array(rows)
    coeffs = np.linalg.solve(V, np.eye(degree)).T  # row i: polynomial for condition i
    return coeffs.reshape(2, order, degree)


def hermite_values(order: int, xi: np.ndarray, derivative: int, length: float) -> np.ndarray:
    """1-D Hermite basis (or its x-derivative) at points ξ, in physical units.

    Returns shape (2, order, len(xi)): entry [end, k] is the basis function
    that carries the k-th *physical* derivative at ``end`` (scaled by
    ``length**k``), differentiated ``derivative`` times with respect to x.
    """
    c = hermite_coefficients(order)
    xi = np.asarray(xi, dtype=float)
    out = np.empty((2, order, xi.size))
    for end in range(2):
        for k in range(order):
            poly = np.polynomial.Polynomial(c[end, k])
            out[end, k] = poly.deriv(derivative)(xi) if derivative else poly(xi)
            out[end, k] *= length**k / length**derivative
    return out


def shape_functions(
    element: ElementType, dx: float, dy: float, xi: np.ndarray, eta: np.ndarray,
    derivative: tuple[int, int] = (0, 0),
) -> np.ndarray:
    """Element shape functions (or a derivative) at points (ξ_i, η_i).

    Returns shape (dofs_per_element, n_points); DOF order is corner-major
    (``CORNERS``), then ``element.nodal_dofs``.
    """
    r = element.hermite_order
    Hx = hermite_values(r, xi, derivative[0], dx)
    Hy = hermite_values(r, eta, derivative[1], dy)
    rows = []
    for ex, ey in CORNERS:
        for name in element.nodal_dofs:
            p, q = DOF_ORDERS[name]
            rows.append(Hx[ex, p] * Hy[ey, q])
    return np.array(rows)


def _gauss_grid(order: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Tensor Gauss–Legendre points on the unit square, exact for the mass integrand."""
    n = 2 * order  # 1-D degree ≤ 2(2r-1) = 4r-2 needs 2r points
    g, wg = np.polynomial.legendre.leggauss(n)
    g = 0.5 * (g + 1.0)
    wg = 0.5 * wg
    XI, ETA = np.meshgrid(g, g, indexing="ij")
    W = np.outer(wg, wg)
    return XI.ravel(), ETA.ravel(), W.ravel()


def flexural_rigidity(youngs_modulus: float, thickness: float, poisson: float) -> float:
    """D = E h³ / (12 (1 − ν²))."""
    return youngs_modulus * thickness**3 / (12.0 * (1.0 - poisson**2))


@lru_cache(maxsize=64)
def _unit_matrices(name: str, dx: float, dy: float, poisson: float) -> tuple[np.ndarray, ...]:
    element = ELEMENTS[name]
    xi, eta, w = _gauss_grid(element.hermite_order)
    area = dx * dy
    N = shape_functions(element, dx, dy, xi, eta)
    Nxx = shape_functions(element, dx, dy, xi, eta, (2, 0))
    Nyy = shape_functions(element, dx, dy, xi, eta, (0, 2))
    Nxy = shape_functions(element, dx, dy, xi, eta, (1, 1))
    wa = w * area
    M1 = (N * wa) @ N.T
    nu = poisson
    K1 = (
        (Nxx * wa) @ Nxx.T
        + (Nyy * wa) @ Nyy.T
        + nu * ((Nxx * wa) @ Nyy.T + (Nyy * wa) @ Nxx.T)
        + 2.0 * (1.0 - nu) * (Nxy * wa) @ Nxy.T
    )
    f1 = N @ wa
    for a in (M1, K1, f1):
        a.setflags(write=False)
    return M1, K1, f1


def element_matrices(
    element: ElementType, dx: float, dy: float, *, rigidity: float, mass_per_area: float,
    poisson: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Consistent mass M_e, stiffness K_e and unit-pressure load f_e of one dx × dy element."""
    M1, K1, f1 = _unit_matrices(element.name, float(dx), float(dy), float(poisson))
    return mass_per_area * M1, rigidity * K1, f1.copy()
