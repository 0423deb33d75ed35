"""The static start (Gnilka 1971, subroutines THESIS and INITAL; appendix E).

The thesis starts at omega t = 0, cam at mid-stroke, in configuration VII
(cam and rocker in contact), from a static state. The linear model's q = 0 is
the unloaded mechanism; the spring preload enters through the cam offset:

1. k_eff, the static stiffness seen at the follower in the starting layer
   (rocker closed, everything else free): k_eff = 1 / (K_L⁻¹)_ff, with f the
   follower (the ``ahead`` coordinate of the cam clearance).
2. On the base circle (cam at q_cam = XZERO - A) the follower force must equal
   the spring preload carried through the rocker:
   k_eff (XZERO - A) = F_s · R, so

       XZERO = A + F_s R / k_eff

3. At omega t = 0 the cam is at mid-stroke, q_cam = XZERO, so the initial
   follower force is FZERO = k_eff · XZERO.

With the thesis data (A = 0.5 in, F_s = 145 lbf, R = 1.5 in / 1.0 in, spring
rate 254 lbf/in) this gives XZERO = 0.88245022 in and FZERO = 501.85073 lbf,
the values of the thesis' sample printout for the 11,000 RPM run.

The initial displacements are the static deflection under FZERO at the
follower, q_L = K_L⁻¹ e_f FZERO (so q_f = XZERO). The initial velocities are
a preset choice (``initial.velocities``):

* ``thesis`` (subroutine INITAL): the follower's values are set equal to the
  cam's, the left rocker's to the pushrod's (ADJUST: a tied pair shares its
  values), and every other velocity starts at zero: q̇_f = q̇_cam(0), the rest
  0. The members then catch up with the cam: the start shock of the thesis'
  run.
* ``quasi-static``: the same deflection shape moving with the cam
  (q̇ = q/XZERO · q̇_cam(0)), so no member starts with a velocity jump.

The accelerations are the consistent ones of the starting configuration
(computed by the back end before the first step).

Linear clearances with an opening (a spring's coil contacts) that the
start's deflection would overlap are closed at the start: the start is then
the affine equilibrium with their springs and constant forces, found by
active sets (:func:`coils_closed_at_start`); the configuration starts with
them closed.

Compliant contacts closed at the start (``contact = "linear"``): an internal
one adds its spring to K_L; a compliant cam contact is a spring k_c in
series with the mechanism, so k_eff above becomes 1 / (1/k_eff + 1/k_c) (the
force per unit cam displacement), the follower sits F/k_eff from its
unloaded place and the contact overlaps by F/k_c.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vtool.errors import InputError
from vtool.solvers.model.layers import Layer
from vtool.solvers.model.spec import ENABLED, INTERNAL, LINEAR, QUASI_STATIC_START, MechanismSpec


@dataclass(frozen=True)
class StaticStart:
    """Cam offset, initial follower force and the initial state over the full coordinates."""

    cam_offset: float  # XZERO, length
    follower_force: float  # FZERO, force
    follower_stiffness: float  # k_eff, force/length
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    closed: tuple[str, ...] = ()  # compliant clearances with an opening closed at the start (coils_closed_at_start)


def cam_clearance(spec: MechanismSpec):
    for c in spec.clearances:
        if c.behind == spec.cam.coordinate:
            return c
    raise InputError("clearances", "no clearance on the cam", f"one clearance with behind = {spec.cam.coordinate}")


def check_open_gaps(spec: MechanismSpec, q: np.ndarray, closed: tuple[str, ...] = ()) -> None:
    """Refuse a start in which a clearance that is not closed would already be penetrated (``closed``: the
    clearances with an opening the static start closed)."""
    length = spec.unit_system.length
    for c in spec.clearances:
        if c.state != ENABLED or c.name in spec.initial.closed or c.name in closed:
            continue
        ahead = q[c.ahead - 1]
        if spec.seat is not None and c.behind == spec.seat.coordinate:
            if ahead - spec.seat.position < -1e-12 * max(abs(ahead), 1.0) and spec.seat.lash is not None:
                raise InputError("seat.lash", spec.seat.lash,
                                 f"a lash below the cam's lift at angle 0, where the run starts with "
                                 f"{', '.join(spec.initial.closed)} closed (initial.closed) and the valve off its "
                                 f"seat (a lift table that starts on the base circle: rotate it so that angle 0 "
                                 f"is on the lift event)", length)
            if ahead - spec.seat.position < -1e-12 * max(abs(ahead), 1.0):
                raise InputError("seat.position", spec.seat.position,
                                 f"<= {ahead:.6g} (where the static start puts q{c.ahead}; the run would "
                                 f"start inside the seat)", length)
        elif c.behind <= spec.n_coordinates:
            gap = c.gap(ahead, q[c.behind - 1] if c.behind > 0 else 0.0)
            if gap < -1e-12 * max(abs(ahead), 1.0) and c.offset:  # e.g. a spring's coils touching at the start
                raise InputError("initial.closed", list(spec.initial.closed),
                                 f"a start with clearance {c.name} open: the static start at cam angle 0 overlaps it "
                                 f"by {-gap:.3g} {length} (a start inside a contact with an opening is not built: "
                                 f"start where it is open, e.g. a spring's coils apart at angle 0)")
            if gap < -1e-12 * max(abs(ahead), 1.0):
                raise InputError("initial.closed", list(spec.initial.closed),
                                 f"a start with clearance {c.name} open or closed consistently (its gap would be "
                                 f"{gap:.3g} {length})")


def start_stiffness(spec: MechanismSpec, layer: Layer) -> np.ndarray:
    """K_L of the starting layer with the springs of the compliant internal contacts closed at the start."""
    K = layer.K.copy()
    for c in spec.clearances:
        if c.rigid or c.name not in spec.initial.closed:
            continue
        if c.kind != INTERNAL and c.behind != spec.cam.coordinate:
            raise InputError("initial.closed", list(spec.initial.closed),
                             f"clearances closed at the start that are rigid, internal or the cam's "
                             f"({c.name} is a compliant contact with a fixed source)")
        if c.kind == INTERNAL:
            w = layer.T[c.ahead - 1] - layer.T[c.behind - 1]
            K += c.contact_stiffness * np.outer(w, w)
    return K


def static_start(spec: MechanismSpec, layer: Layer, omega: float, final: bool = True) -> StaticStart:
    """Apply the thesis' static-start rule in the starting layer (see module doc). ``final`` False: the
    harmonic rule's linear start that a table cam's start scales (:func:`vtool.solvers.model.cam.table_start`,
    which then calls :func:`start_state`), not checked here."""
    cam = cam_clearance(spec)
    follower = cam.ahead
    f = int(np.argmax(layer.T[follower - 1]))  # the follower's column in the layer
    try:
        flexibility = np.linalg.solve(start_stiffness(spec, layer), np.eye(layer.size)[:, f])
    except np.linalg.LinAlgError:
        raise InputError(
            "members", "no spring to ground", "a mechanism that is statically stable with the cam released"
        ) from None
    follower_stiffness = 1.0 / flexibility[f]
    structure_stiffness = follower_stiffness
    follower_share = 1.0  # follower displacement per unit cam displacement
    if not cam.rigid and cam.name in spec.initial.closed:
        series = 1.0 / (1.0 / follower_stiffness + 1.0 / cam.contact_stiffness)
        follower_share = series / follower_stiffness
        follower_stiffness = series
    amplitude = spec.cam.amplitude
    if spec.cam.offset is None:
        cam_offset = amplitude + spec.initial.spring_preload * spec.initial.lever_ratio / follower_stiffness
    else:
        cam_offset = spec.cam.offset
    follower_force = follower_stiffness * cam_offset
    shape = layer.T @ (flexibility * structure_stiffness)  # q per unit follower displacement
    if follower_share != 1.0:
        shape = shape * follower_share  # per unit cam displacement
    cam_velocity = amplitude * omega  # d/dt (A sin wt) at t = 0
    cam_acceleration = 0.0  # -A w² sin(0)
    q = shape * cam_offset
    closed: tuple[str, ...] = ()
    if final:
        q, shape, closed, force = start_state(spec, layer, cam_offset, shape, follower_share == 1.0)
        follower_force = follower_force if force is None else force
    if spec.initial.velocities == QUASI_STATIC_START:
        qd, qdd = shape * cam_velocity, shape * cam_acceleration
    else:  # the thesis' INITAL: the follower moves with the cam, everything else at rest
        qd, qdd = np.zeros_like(shape), np.zeros_like(shape)
        qd[follower - 1], qdd[follower - 1] = cam_velocity, cam_acceleration
    return StaticStart(
        cam_offset=cam_offset,
        follower_force=follower_force,
        follower_stiffness=follower_stiffness,
        q=q,
        qd=qd,
        qdd=qdd,
        closed=closed,
    )


def start_state(spec: MechanismSpec, layer: Layer, X: float, shape: np.ndarray, rigid_cam: bool = True
                ) -> tuple[np.ndarray, np.ndarray, tuple[str, ...], float | None]:
    """(q, dq/dX, closed, follower force or None) of the start with the follower at X: the linear shape X, or,
    where that overlaps a linear clearance with an opening (a spring's coils touching at the start, rigid cam
    contact), :func:`coils_closed_at_start`; checked by :func:`check_open_gaps`."""
    q = shape * X
    if rigid_cam and any(c.offset and c.contact == LINEAR and c.name not in spec.initial.closed
                         and c.gap(q[c.ahead - 1], q[c.behind - 1] if c.behind else 0.0) < 0.0
                         for c in spec.clearances if 0 <= c.behind <= spec.n_coordinates):
        f = int(np.argmax(layer.T[cam_clearance(spec).ahead - 1]))
        q, shape, closed, force = coils_closed_at_start(spec, layer, f, X)
        check_open_gaps(spec, q, closed)
        return q, shape, closed, force
    check_open_gaps(spec, q)
    return q, shape, (), None


def coils_closed_at_start(spec: MechanismSpec, layer: Layer, f: int,
                          cam_offset: float) -> tuple[np.ndarray, np.ndarray, tuple[str, ...], float]:
    """The static start with the linear clearances that have an opening (a spring's coil contacts) closed where
    the start overlaps them: (q, dq/dq_cam, their names, the follower force).

    With the cam's follower at z_f = X (rigid cam contact), the layer's equilibrium with the closed contacts'
    springs k w wᵀ and their constant forces k o w (w the gap's gradient on the layer, o the opening) is affine
    in X: z_F = -K_FF⁻¹ (K_Ff X + b_F), b = Σ k o w. The closed set is found by active sets: close every
    such clearance whose gap is negative, open every closed one whose gap is positive, until none changes
    (at most one pass per clearance)."""
    candidates = [c for c in spec.clearances
                  if c.offset and c.contact == LINEAR and 0 <= c.behind <= spec.n_coordinates
                  and c.name not in spec.initial.closed]
    K0 = start_stiffness(spec, layer)
    free = [j for j in range(layer.size) if j != f]
    closed: set[str] = set()
    for _ in range(len(candidates) + 1):
        K, b = K0.copy(), np.zeros(layer.size)
        for c in candidates:
            if c.name in closed:
                w = c.sense * layer.T[c.ahead - 1] - (c.sense * layer.T[c.behind - 1] if c.behind else 0.0)
                K += c.contact_stiffness * np.outer(w, w)
                b += c.contact_stiffness * c.opening * w
        z, dz = np.zeros(layer.size), np.zeros(layer.size)
        z[f], dz[f] = cam_offset, 1.0
        z[free] = -np.linalg.solve(K[np.ix_(free, free)], K[free, f] * cam_offset + b[free])
        dz[free] = -np.linalg.solve(K[np.ix_(free, free)], K[free, f])
        q = layer.T @ z
        now = {c.name for c in candidates if c.gap(q[c.ahead - 1], q[c.behind - 1] if c.behind else 0.0) < 0.0
               or (c.name in closed and c.gap(q[c.ahead - 1], q[c.behind - 1] if c.behind else 0.0) <= 0.0)}
        if now == closed:
            break
        closed = now
    force = float(K[f] @ z + b[f])
    return q, layer.T @ dz, tuple(c.name for c in candidates if c.name in closed), force
