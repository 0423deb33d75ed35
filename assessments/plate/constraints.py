"""Simply supported edges as kinematic constraints (thesis Tables 2 and 3 notes).

Edges parallel to x (y = 0, y = b): w = 0 along the edge, so its derivatives
along x vanish too::

    16-DOF:  w = w_x = 0
    24-DOF:  w = w_x = w_xx = 0, and w_yy = 0

Edges parallel to y (x = 0, x = a), with x and y swapped::

    16-DOF:  w = w_y = 0
    24-DOF:  w = w_y = w_yy = 0, and w_xx = 0

For the 24-DOF element the edge-normal curvature is also set to zero: with
w_xx = 0 along an x-edge the zero bending moment M_y = −D (w_yy + ν w_xx) = 0
needs w_yy = 0. That is the set that gives the thesis' 82 constrained DOF on
the 4 × 4 mesh: 25 nodes × 6 = 150 unknowns, minus 4 on each of the 12
edge (non-corner) nodes, minus 5 on each of the 4 corners (only w_xy stays
free there): 150 − 48 − 20 = 82. Taking only w, the tangential slope and
the tangential curvature (3 per edge node) would leave 94; the 16-DOF rule
leaves 100 − 12 × 2 − 4 × 3 = 64.

The constrained ("free") DOFs are those left; ``restrict`` removes the rows
and columns of the constrained ones (thesis eq. 19).
"""

from __future__ import annotations

import numpy as np

from vtool.assessments.plate.assembly import Mesh

#: Unknowns set to zero at nodes of an edge parallel to x / parallel to y.
EDGE_PARALLEL_X: dict[str, tuple[str, ...]] = {
    "bfs16": ("w", "wx"),
    "mason24": ("w", "wx", "wxx", "wyy"),
}
EDGE_PARALLEL_Y: dict[str, tuple[str, ...]] = {
    "bfs16": ("w", "wy"),
    "mason24": ("w", "wy", "wyy", "wxx"),
}


def constrained_dofs(mesh: Mesh) -> np.ndarray:
    """Sorted global indices of the DOFs fixed at zero by the simply supported edges."""
    name = mesh.element.name
    fixed: set[int] = set()
    for j in range(mesh.ny + 1):
        for i in range(mesh.nx + 1):
            names: set[str] = set()
            if j in (0, mesh.ny):
                names.update(EDGE_PARALLEL_X[name])
            if i in (0, mesh.nx):
                names.update(EDGE_PARALLEL_Y[name])
            fixed.update(mesh.dof(i, j, n) for n in names)
    return np.array(sorted(fixed), dtype=int)


def free_dofs(mesh: Mesh) -> np.ndarray:
    """Sorted global indices of the unconstrained DOFs (the thesis' 'constrained DOF' set)."""
    return np.setdiff1d(np.arange(mesh.n_dofs), constrained_dofs(mesh))


def restrict(mesh: Mesh) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(M_c, K_c, f_c, free): matrices of the supported plate over its free DOFs."""
    M, K, f = mesh.matrices
    free = free_dofs(mesh)
    ix = np.ix_(free, free)
    return M[ix].copy(), K[ix].copy(), f[free].copy(), free
