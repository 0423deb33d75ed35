"""Configurations: which clearances are closed, and the matrices each one needs.

n clearances give 2ⁿ configurations. A configuration is a bit mask with
contact = 1; clearance 1 (the first in the preset) is the leading bit, so for
the thesis' three clearances ``mask + 1`` is its configuration number I–VIII
(Gnilka 1971, Fig. 3.1: VII = 110 = cam and rocker closed). Pinned
clearances are always closed, removed ones never.

Partitioning one configuration
------------------------------
Closed internal clearances select the contact layer (see
:mod:`vtool.solvers.model.layers`), with layer matrices M_L, C_L, K_L over the m
layer coordinates. Each closed external clearance prescribes the layer
coordinate of its ``ahead`` end to follow its source (cam, seat). With P the
prescribed and F the free layer coordinates,

    ⎡M_FF M_FP⎤ ⎧ä_F⎫   ⎡C_FF C_FP⎤ ⎧v_F⎫   ⎡K_FF K_FP⎤ ⎧x_F⎫   ⎧0  ⎫
    ⎣M_PF M_PP⎦ ⎩ä_P⎭ + ⎣C_PF C_PP⎦ ⎩v_P⎭ + ⎣K_PF K_PP⎦ ⎩x_P⎭ = ⎩F_P⎭

The F rows are integrated (the P columns move to the right-hand side: the
thesis' ΔP, eqs. 3.32–3.34); the P rows give the external contact forces
(eqs. 3.35–3.36).

Contact forces on full coordinates
----------------------------------
With T the layer expansion (q = T q_L), the force on every full coordinate is
taken as r = M T ä_L + M T M_L⁻¹ C_L v̇_L + K T q_L: the stiffness and inertia
forces of the full system, and the layer's modal damping forces distributed
in proportion to mass. Summed over a tied pair, r gives exactly the layer
equation (Tᵀr = M_L ä + C_L v + K_L x), so the internal contact force on the
ahead coordinate and the one on the behind coordinate are equal and opposite
(thesis F8 = −F2). A contact force is r at the clearance's ``ahead``
coordinate, positive in compression. (A coordinate that is the ahead end of
an external clearance must not also be tied by an internal one.)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vtool.solvers.model.layers import Layer
from vtool.solvers.model.mechanism import Mechanism
from vtool.solvers.model.spec import (
    EXTERNAL,
    HERTZ,
    INTERNAL,
    PINNED,
    REMOVED,
    ClearanceSpec,
    MechanismSpec,
)

ROMAN = ("I", "II", "III", "IV", "V", "VI", "VII", "VIII")

HARMONIC_SOURCE = 0
FIXED_SOURCE = 1
UNIT_SOURCE = 0  # the coordinate number of the unit source (see unit_source): the ground's number


def clearance_bit(spec: MechanismSpec, index: int) -> int:
    """Bit of clearance ``index`` (0-based, preset order): clearance 1 leads."""
    return 1 << (len(spec.clearances) - 1 - index)


def mask_of(spec: MechanismSpec, closed: set[str] | frozenset[str] | tuple[str, ...]) -> int:
    """Configuration mask with these clearances (and every pinned one) closed."""
    mask = 0
    for index, c in enumerate(spec.clearances):
        if (c.name in closed or c.state == PINNED) and c.state != REMOVED:
            mask |= clearance_bit(spec, index)
    return mask


def closed_names(spec: MechanismSpec, mask: int) -> tuple[str, ...]:
    return tuple(c.name for i, c in enumerate(spec.clearances) if mask & clearance_bit(spec, i))


def thesis_number(spec: MechanismSpec, mask: int) -> int | None:
    """The thesis' configuration number 1–8 where it applies (three clearances)."""
    return mask + 1 if len(spec.clearances) == 3 else None


def configuration_label(spec: MechanismSpec, mask: int) -> str:
    """'VII (cam+rocker)' for the thesis' three clearances, else the closed names."""
    closed = "+".join(closed_names(spec, mask)) or "none"
    number = thesis_number(spec, mask)
    return f"{ROMAN[number - 1]} ({closed})" if number is not None else closed


def sources(spec: MechanismSpec) -> list[tuple[int, int, tuple[float, float, float]]]:
    """Prescribed coordinates: (coordinate number, kind, parameters), cam first.

    The cam's parameters need the cam speed and offset, filled in by
    :func:`source_parameters`.
    """
    result = [(spec.cam.coordinate, HARMONIC_SOURCE, (spec.cam.amplitude, 0.0, 0.0))]
    if spec.seat is not None:
        result.append((spec.seat.coordinate, FIXED_SOURCE, (spec.seat.position, 0.0, 0.0)))
    if any(c.offset for c in spec.clearances):
        result.append((UNIT_SOURCE, FIXED_SOURCE, (1.0, 0.0, 0.0)))
    return result


def unit_source(spec: MechanismSpec) -> int:
    """Index of the unit source (x ≡ 1, numbered :data:`UNIT_SOURCE`), present when a clearance's gap has an
    offset (:attr:`ClearanceSpec.offset`): the constant force k·opening of its closed contact is a column
    on it, and the ground (behind = 0) is this source with the opening moved by the sense; -1 without one."""
    entries = sources(spec)
    return len(entries) - 1 if entries[-1][0] == UNIT_SOURCE else -1


def kernel_opening(c: ClearanceSpec) -> float:
    """The opening the back ends add to sense·(q_ahead - x_behind): the ground (behind = 0) is the unit
    source at x = 1, so its opening grows by the sense (sense·(q - 0) + o = sense·(q - 1) + o + sense)."""
    return c.opening + (c.sense if c.behind == 0 else 0.0)


def source_parameters(mechanism: Mechanism) -> tuple[np.ndarray, np.ndarray, list[int]]:
    """(kind[ns], par[ns, 3], coordinate numbers) of the prescribed sources."""
    entries = sources(mechanism.spec)
    kinds = np.array([kind for _, kind, _ in entries], dtype=np.int64)
    par = np.zeros((len(entries), 3))
    for s, (_, kind, values) in enumerate(entries):
        par[s] = values
        if kind == HARMONIC_SOURCE:
            par[s] = (mechanism.spec.cam.amplitude, mechanism.omega, mechanism.start.cam_offset)
    return kinds, par, [number for number, _, _ in entries]


@dataclass(frozen=True)
class Partition:
    """One configuration split into its layer, free and prescribed layer coordinates."""

    layer: Layer
    group: np.ndarray  # layer column of each full coordinate
    free: list[int]
    prescribed: list[int]
    sources: list[int]  # source index of each prescribed column
    C: np.ndarray  # the configuration's modal damping over the layer's coordinates (see partition)


def partition(mechanism: Mechanism, mask: int) -> Partition:
    """Layer of the closed rigid internal clearances; closed rigid external ones prescribe their ahead end.

    Modal damping belongs to the contact state, not to the contact law: with
    closed compliant internal contacts the configuration keeps the damping
    C_t of the layer in which those pairs are tied (the preset's
    ``damping.layers`` entry that names them), spread over each pair: with
    R the map from the tied layer's coordinates to this layer's (q = R q_t)
    and G = RᵀR, C = R G⁻¹ C_t G⁻¹ Rᵀ, so that Rᵀ C R = C_t. As the contact
    stiffness grows the run so approaches the rigid run's.
    """
    spec = mechanism.spec
    closed = closed_names(spec, mask)
    layer = mechanism.layer(frozenset(n for n in closed if spec.clearance(n).ties))
    damping = layer.C
    soft = frozenset(n for n in closed if spec.clearance(n).kind == INTERNAL and not spec.clearance(n).rigid)
    if soft:
        tied = mechanism.tied_layer(frozenset(n for n in closed if spec.clearance(n).kind == INTERNAL))
        R = np.linalg.solve(layer.T.T @ layer.T, layer.T.T @ tied.T)
        spread = R @ np.linalg.inv(R.T @ R)
        damping = spread @ tied.C @ spread.T
    group = np.argmax(layer.T, axis=1)
    source_of = {number: s for s, (number, _, _) in enumerate(sources(spec))}
    prescribed: dict[int, int] = {}
    for c in spec.clearances:
        if c.kind == EXTERNAL and c.rigid and c.name in closed:
            prescribed[int(group[c.ahead - 1])] = source_of[c.behind]
    pres = sorted(prescribed)
    free = [j for j in range(layer.size) if j not in prescribed]
    return Partition(layer, group, free, pres, [prescribed[j] for j in pres], damping)


def internal_force_coefficients(
    mechanism: Mechanism, mask: int, ahead: int, behind: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict[int, float]]:
    """Coefficients of an internal clearance's contact force while it is closed in ``mask``.

    The force is the pair force (+λ on ahead, -λ on behind) that keeps the
    clearance shut under the equations of the configuration in which it is
    open (``mask`` without it): with that configuration's free accelerations
    a_F = M_FF⁻¹ (f_F - C_FF v_F - K_FF x_F - M_FP a_P - C_FP v_P - K_FP x_P)
    and w selecting ahead minus behind, λ = -(wᵀ a)|_(λ=0) / (w_Fᵀ M_FF⁻¹ w_F).
    This is linear in the full state and the sources, so it is returned as
    (fx[n], fv[n], fs[ns, 3]) with λ = fx·q + fv·q̇ + Σ_s fs[s]·(q_s, q̇_s, q̈_s),
    and a coefficient per closed Hertz contact j (its force F_j w_j adds
    scale · rowᵀ w_j F_j).
    """
    spec = mechanism.spec
    bit = next(clearance_bit(spec, i) for i, c in enumerate(spec.clearances)
               if (c.ahead, c.behind) == (ahead, behind))
    part = partition(mechanism, mask & ~bit)
    layer, free, pres = part.layer, part.free, part.prescribed
    g = np.zeros(spec.n_coordinates)
    g[ahead - 1], g[behind - 1] = 1.0, -1.0
    w = layer.T.T @ g  # selection over the open layer's coordinates
    springs = compliant_terms(mechanism, mask & ~bit)
    M, C, K = layer.M, part.C + springs.layer_C(layer.T), layer.K + springs.layer_K(layer.T)
    S = layer.T.T @ springs.S
    row = np.linalg.solve(M[np.ix_(free, free)], w[free])  # M_FF⁻¹ w_F (M symmetric)
    scale = -1.0 / float(w[free] @ row)  # λ = scale * (relative acceleration with λ = 0)
    fx = np.zeros(spec.n_coordinates)
    fv = np.zeros(spec.n_coordinates)
    kept = [k - 1 for k in layer.kept]
    coeff_x = -row @ K[np.ix_(free, free)]
    coeff_v = -row @ C[np.ix_(free, free)]
    for f, j in enumerate(free):
        fx[kept[j]] += scale * coeff_x[f]
        fv[kept[j]] += scale * coeff_v[f]
    fs = np.zeros((len(sources(spec)), 3))
    for j, source in zip(pres, part.sources, strict=True):
        fs[source, 0] += scale * -(row @ K[free, j])
        fs[source, 1] += scale * -(row @ C[free, j])
        fs[source, 2] += scale * (w[j] - row @ M[free, j])
    fs -= scale * (row @ S[free]).reshape(fs.shape)
    fh = {j: float(scale * (row @ (layer.T.T @ w)[free])) for j, w in springs.hertz.items()}
    return fx, fv, fs, fh


@dataclass(frozen=True)
class CompliantTerms:
    """The springs and dashpots of the closed compliant clearances of one configuration.

    Over the full coordinates q and the sources' (x, v, a) vector src (the
    kernel's layout, s-major), the contact forces of the closed linear
    clearances add to the equations of motion

        M q̈ + C q̇ + K q + (ΔC q̇ + ΔK q + S src) = 0

    with, per clearance, ΔK = k w wᵀ, ΔC = c w wᵀ (w = e_ahead - e_behind),
    and for an external one (behind = source s) w = e_ahead and S[ahead, 3s] =
    -k, S[ahead, 3s + 1] = -c. Its contact force, positive in compression, is
    F = k δ + c δ̇ with the overlap δ = -(q_ahead - q_behind): the row
    ``force[k]`` on (q, q̇, q̈, src, 1) of the monitor layout.
    """

    K: np.ndarray  # n x n
    C: np.ndarray
    S: np.ndarray  # n x 3 ns
    force: dict[int, np.ndarray]  # clearance index -> row on (q, q̇, q̈, src)
    hertz: dict[int, np.ndarray]  # closed Hertz clearance -> w over the full coordinates (its force acts as F w)

    def layer_K(self, T: np.ndarray) -> np.ndarray:
        return T.T @ self.K @ T

    def layer_C(self, T: np.ndarray) -> np.ndarray:
        return T.T @ self.C @ T


def contact_damping(mechanism: Mechanism, index: int) -> float:
    """Dashpot c of a linear clearance: its own, or 2 ζ √(k m) on the local masses (see ClearanceSpec)."""
    c = mechanism.spec.clearances[index]
    if c.contact_damping is not None:
        return float(c.contact_damping)
    ratio = c.contact_damping_ratio or 0.0
    m = mechanism.M[c.ahead - 1, c.ahead - 1]
    if c.kind == INTERNAL:
        mb = mechanism.M[c.behind - 1, c.behind - 1]
        m = m * mb / (m + mb)
    return float(2.0 * ratio * np.sqrt(c.contact_stiffness * m))


def compliant_terms(mechanism: Mechanism, mask: int) -> CompliantTerms:
    """:class:`CompliantTerms` of the compliant clearances closed in ``mask`` (a Hertz one is nonlinear:
    only its direction w, see :func:`hertz_row`)."""
    spec = mechanism.spec
    n, ns = spec.n_coordinates, len(sources(spec))
    K, C, S = np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, 3 * ns))
    force: dict[int, np.ndarray] = {}
    hertz: dict[int, np.ndarray] = {}
    source_of = {number: s for s, (number, _, _) in enumerate(sources(spec))}
    for index, c in enumerate(spec.clearances):
        if c.rigid or not mask & clearance_bit(spec, index):
            continue
        w = np.zeros(n)  # the gap's gradient: sense (e_ahead - e_behind)
        w[c.ahead - 1] = c.sense
        if c.kind == INTERNAL:
            w[c.behind - 1] = -c.sense
        if c.contact == HERTZ:
            hertz[index] = w
            continue
        k, d = c.contact_stiffness, contact_damping(mechanism, index)
        row = np.zeros(3 * n + 3 * ns)
        if c.kind != INTERNAL:
            s = source_of[c.behind]
            S[c.ahead - 1, 3 * s], S[c.ahead - 1, 3 * s + 1] = -k, -d
            row[3 * n + 3 * s], row[3 * n + 3 * s + 1] = c.sense * k, c.sense * d
        if c.offset:  # the opening's constant force k o w (on the unit source's x ≡ 1), in the force -k o
            u, o = unit_source(spec), kernel_opening(c)
            S[:, 3 * u] += k * o * w
            row[3 * n + 3 * u] -= k * o
        K += k * np.outer(w, w)
        C += d * np.outer(w, w)
        row[:n], row[n:2 * n] = -k * w, -d * w
        force[index] = row
    return CompliantTerms(K, C, S, force, hertz)


def hertz_row(mechanism: Mechanism, index: int) -> np.ndarray:
    """The monitor row of a closed Hertz clearance: -w on q and on q̇, +1 on its source's x and v, so that
    the row's q part gives the overlap δ and its q̇ part δ̇ (the kernel's ``overlap_and_rate``)."""
    spec = mechanism.spec
    n, ns = spec.n_coordinates, len(sources(spec))
    c = spec.clearances[index]
    row = np.zeros(3 * n + 3 * ns)
    row[c.ahead - 1] = row[n + c.ahead - 1] = -c.sense
    if c.kind == INTERNAL:
        row[c.behind - 1] = row[n + c.behind - 1] = c.sense
    else:
        s = next(s for s, (number, _, _) in enumerate(sources(spec)) if number == c.behind)
        row[3 * n + 3 * s] = row[3 * n + 3 * s + 1] = c.sense
    if c.offset:  # δ = -gap: less the opening, on the unit source's x ≡ 1
        row[3 * n + 3 * unit_source(spec)] -= kernel_opening(c)
    return row
