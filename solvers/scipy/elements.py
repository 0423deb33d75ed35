"""Nonlinear elements in a configuration's equations (:mod:`vtool.solvers.model.nonlinear`), for the scipy back end.

With the configuration's state y = (z_F, ż_F) (:mod:`vtool.solvers.exact.piecewise`)
and a force f on the full coordinates, the full coordinates are selected
from the layer's (x = Sel z, every merged coordinate moving with its layer
coordinate), so f acts on the free layer coordinates as Selᵀ f and

    z̈_F += R f,   R = M_FF⁻¹ Selᵀ_F          (the accelerations)
    q̈   += Sel_F R f                         (every free coordinate's)
    F_k += Φ_k f                             (the closed rigid contacts' forces)

A closed rigid external contact's force is the row force at its ahead
coordinate (:mod:`vtool.solvers.model.contact`, ``_monitors``): its share is
its acceleration row's on R f, less f at that coordinate. A closed rigid
internal contact's force is the pair force that keeps it shut under the
equations of the configuration where it is open
(:func:`vtool.solvers.model.configurations.internal_force_coefficients`): its
share is scale · T_F M_FF⁻¹ w_F of that configuration. Compliant contacts'
forces follow from their overlaps: no share. A force on a coordinate that is
prescribed by a closed contact other than at that contact's ahead end is not
seen (none of the elements built here acts on one: the HLA's member end, the
valve head at the seat).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vtool.solvers.exact.statespace import StateSpace
from vtool.solvers.model.configurations import clearance_bit, partition
from vtool.solvers.model.contact import ContactProblem
from vtool.solvers.model.spec import ENABLED, INTERNAL
from vtool.solvers.newmark import layout


@dataclass(frozen=True)
class ElementTerms:
    """One configuration's maps of a coordinate force f (module doc)."""

    nf: int
    Px: np.ndarray  # (n, 2nf): the full coordinates from y (plus Qx u(t))
    Qx: np.ndarray
    Pv: np.ndarray
    Qv: np.ndarray
    R: np.ndarray  # (nf, n)
    Sel: np.ndarray  # (n, nf)
    Phi: np.ndarray  # (ncl, n)


def terms(problem: ContactProblem, ss: StateSpace) -> ElementTerms:
    """The maps of configuration ``ss`` (cached on it)."""
    if "elements" in ss.cache:
        return ss.cache["elements"]
    assert ss.P is not None and ss.Q is not None  # (set by the piecewise state_space)
    n, ncl = problem.n, problem.ncl
    layer = problem.tables.layers[ss.mask]
    nf = layer.nf
    Sel = ss.P[:n, :nf]
    R = np.linalg.solve(layer.M[:nf, :nf], Sel.T) if nf else np.zeros((0, n))
    Phi = np.zeros((ncl, n))
    _, _, _, mk, mon = problem.tables.of(ss.mask)
    spec, mechanism = problem.spec, problem.mechanism
    for k, c in enumerate(spec.clearances):
        if int(mk[k, layout.MK_KIND]) != layout.MK_FORCE:
            continue
        if c.kind == INTERNAL and c.state == ENABLED:
            Phi[k] = internal_share(mechanism, ss.mask, k)
        else:
            Phi[k] = mon[k, 2 * n:2 * n + nf] @ R
            Phi[k, c.ahead - 1] -= 1.0
    out = ElementTerms(nf, ss.P[:n], ss.Q[:n], ss.P[n:2 * n], ss.Q[n:2 * n], R, Sel, Phi)
    ss.cache["elements"] = out
    return out


def internal_share(mechanism, mask: int, index: int) -> np.ndarray:  # noqa: ANN001 (a Mechanism)
    """Φ_k of a closed rigid internal contact: its force per unit force on each full coordinate."""
    spec = mechanism.spec
    c = spec.clearances[index]
    part = partition(mechanism, mask & ~clearance_bit(spec, index))
    layer, free = part.layer, part.free
    g = np.zeros(spec.n_coordinates)
    g[c.ahead - 1], g[c.behind - 1] = 1.0, -1.0
    w = layer.T.T @ g
    row = np.linalg.solve(layer.M[np.ix_(free, free)], w[free])
    scale = -1.0 / float(w[free] @ row)
    return scale * (layer.T[:, free] @ row)
