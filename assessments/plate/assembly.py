"""Rectangular plate meshes and assembly of the global M, K and load vectors.

An ``nx × ny`` mesh of equal ``a/nx × b/ny`` elements. Node (i, j) sits at
``(i a/nx, j b/ny)`` with ``i = 0..nx`` along x and ``j = 0..ny`` along y; its
number is ``j (nx + 1) + i`` and its unknowns follow ``element.nodal_dofs``, so
global DOF ``node * dofs_per_node + k`` is the k-th nodal unknown of ``node``.

Matrices are dense: the thesis' largest problem has 82 unknowns and the
convergence studies stay below a few thousand.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from vtool.assessments.plate.elements import (
    CORNERS,
    ELEMENTS,
    ElementType,
    element_matrices,
    flexural_rigidity,
    shape_functions,
)


@dataclass(frozen=True)
class Plate:
    """An isotropic rectangular plate: sides a (x), b (y), thickness, E, ν, density."""

    a: float
    b: float
    thickness: float
    youngs_modulus: float
    poisson: float
    density: float

    @property
    def rigidity(self) -> float:
        """Flexural rigidity D = E h³ / (12 (1 − ν²))."""
        return flexural_rigidity(self.youngs_modulus, self.thickness, self.poisson)

    @property
    def mass_per_area(self) -> float:
        """ρh."""
        return self.density * self.thickness


@dataclass(frozen=True)
class Mesh:
    """A regular nx × ny mesh of one element type over a plate."""

    plate: Plate
    element: ElementType
    nx: int
    ny: int

    @property
    def dx(self) -> float:
        return self.plate.a / self.nx

    @property
    def dy(self) -> float:
        return self.plate.b / self.ny

    @property
    def n_nodes(self) -> int:
        return (self.nx + 1) * (self.ny + 1)

    @property
    def n_dofs(self) -> int:
        return self.n_nodes * self.element.dofs_per_node

    def node(self, i: int, j: int) -> int:
        return j * (self.nx + 1) + i

    def dof(self, i: int, j: int, name: str) -> int:
        """Global index of nodal unknown ``name`` (e.g. ``"wx"``) at node (i, j)."""
        return self.node(i, j) * self.element.dofs_per_node + self.element.nodal_dofs.index(name)

    def dof_label(self, index: int) -> str:
        """``"w@2,2"`` style label of a global DOF."""
        node, k = divmod(index, self.element.dofs_per_node)
        j, i = divmod(node, self.nx + 1)
        return f"{self.element.nodal_dofs[k]}@{i},{j}"

    def element_dofs(self, ex: int, ey: int) -> np.ndarray:
        """Global DOF numbers of element (ex, ey) in the element's corner-major order."""
        ndof = self.element.dofs_per_node
        out: list[int] = []
        for cx, cy in CORNERS:
            base = self.node(ex + cx, ey + cy) * ndof
            out.extend(range(base, base + ndof))
        return np.array(out)

    @cached_property
    def matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Assembled (M, K, f): mass, stiffness and unit-uniform-pressure load, unconstrained."""
        plate = self.plate
        Me, Ke, fe = element_matrices(
            self.element, self.dx, self.dy, rigidity=plate.rigidity,
            mass_per_area=plate.mass_per_area, poisson=plate.poisson,
        )
        n = self.n_dofs
        M = np.zeros((n, n))
        K = np.zeros((n, n))
        f = np.zeros(n)
        for ey in range(self.ny):
            for ex in range(self.nx):
                d = self.element_dofs(ex, ey)
                ix = np.ix_(d, d)
                M[ix] += Me
                K[ix] += Ke
                f[d] += fe
        for arr in (M, K, f):
            arr.setflags(write=False)
        return M, K, f

    def point_vector(self, x: float, y: float) -> np.ndarray:
        """Row e with w(x, y) = e · u for the global DOF vector u.

        The same vector is the consistent load of a unit point force at (x, y).
        """
        ex = min(int(np.floor(x / self.dx + 1e-12)), self.nx - 1)
        ey = min(int(np.floor(y / self.dy + 1e-12)), self.ny - 1)
        xi = np.array([x / self.dx - ex])
        eta = np.array([y / self.dy - ey])
        N = shape_functions(self.element, self.dx, self.dy, xi, eta)[:, 0]
        e = np.zeros(self.n_dofs)
        e[self.element_dofs(ex, ey)] = N
        return e


def make_mesh(plate: Plate, element: str, nx: int, ny: int) -> Mesh:
    """A mesh from an element name (``"bfs16"`` or ``"mason24"``)."""
    return Mesh(plate, ELEMENTS[element], int(nx), int(ny))
