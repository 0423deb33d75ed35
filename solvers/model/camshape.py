"""The cam's shape from a lift law and a follower: profile, curvature, pressure angle, finger kinematics.

Frames and angles. The follower frame has the follower's line of action
(translating followers) or the cam-centre-to-roller direction at the base
circle (finger followers) along +y; the cam turns in the frame's positive
sense by θ (cam angle, rad, from the preset's angle zero). The lift law
L(ψ) (length, ψ in rad of the law) is the follower's lift for a follower on
that reference line: a flat face's lift, or the lift of the centre of a
roller of radius r_r along the line (the "cam lift" a grinder's table gives
for that roller). With J the rotation by +90° (J(x, y) = (-y, x)), a point
f(ψ) fixed to the follower frame at law angle ψ lies in the cam's own frame
at p = R(-ψ) f, with

    p' = R(-ψ) g1,  g1 = f' - J f;   p'' = R(-ψ) g2,  g2 = f'' - 2 J f' - f,

so the cam-frame curve's signed radius of curvature is -|g1|³ / (g1 × g2)
(positive where the cam is convex; the curve is traversed clockwise).

* Flat face: the contact point is f = (L', r_b + L) (offset L' along the
  face: its travel), so g1 = (r_b + L + L'', 0) and the radius is
  r_b + L + L'' (Dowson & Higginson's result; the code takes it from the
  general formula above, and the tests check the identity).
* Roller: the roller centre runs on the pitch curve f = (0, R), R = R0 + L,
  R0 = r_b + r_r, whose radius is ρ_p = (R² + L'²)^{3/2} / (R² + 2L'² - R L'')
  and whose outward normal is J g1/|g1| = (-L', R)/√(R² + L'²); the cam
  profile is the pitch curve moved in by r_r, with radius ρ_p - r_r. The
  pressure angle of a translating roller is atan(L'/R).
* Undercut: a flat face's radius r_b + L + L'' <= 0, or a roller larger than
  the pitch curve's convex radius (0 < ρ_p <= r_r): the profile would cross
  itself and the follower cannot follow the law. :func:`cam_profile` lists
  the law-angle intervals where it happens (linear interpolation of
  ρ (flat) or 1 - r_r/ρ_p (roller) between samples).

End-pivot finger follower (:class:`vtool.solvers.model.spec.FingerSpec`):
the finger turns by φ about its pivot P = 0; the roller centre is
Q(φ) = R(φ) Q0, the pad centre D(φ) = R(φ) D0 with D0 = (b, 0), so the valve
(axis along +y through the pad) lifts V(φ) = b sin φ. The cam centre C sits at
|Q0 - C| = R0. The roller touches the cam when its centre lies on the pitch
curve, which in the fixed frame at cam angle θ is the polar curve
r(δ) = R0 + L(θ - δ) (δ: the angle of Q - C from the reference Q0 - C):

    F(φ, θ) = |Q(φ) - C| - R0 - L(θ - δ(φ)) = 0

solved for φ by Newton's method from φ = 0 (the base circle), all angles at
once. The law angle at the contact is ψ = θ - δ. The finger's effective
ratio is the valve lift per unit radial lift u = |Q - C| - R0 of the roller:

    r(θ) = dV/du = b cos φ / ((Q - C)·Q'/|Q - C|),   Q' = J Q,

which the tests check against a finite difference of V and u from a direct
(brentq) solution of the contact. The dynamics' cam coordinate moves as the
geometric valve lift over the model's nominal ratio b/a
(:func:`model_lift`: the valve side of the model's lever then follows V
exactly), and the normal contact force is F_n = F_model (a/b) V'(φ) / (n·Q'),
n the contact normal (virtual work).

Offset translating followers and flat-faced fingers are not modelled.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vtool.errors import InputError
from vtool.solvers.model.cam import derivatives, lift_series
from vtool.solvers.model.spec import FLAT, LEVERS, ROCKER, CamSpec, FollowerSpec

NEWTON_STEPS = 60
NEWTON_TOLERANCE = 1e-12  # of the pitch radius R0


def law_derivatives(law: CamSpec, psi: np.ndarray) -> np.ndarray:
    """Rows L, L', L'', L''' of a lift law at law angles ψ (rad)."""
    return derivatives(*lift_series(law), np.asarray(psi, dtype=float))


def _J(v: np.ndarray) -> np.ndarray:
    return np.array([-v[1], v[0]])


def _frames(f: np.ndarray, df: np.ndarray, ddf: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """g1, g2 (follower-frame images of p', p'') and g1 × g2."""
    g1 = df - _J(f)
    g2 = ddf - 2.0 * _J(df) - f
    return g1, g2, g1[0] * g2[1] - g1[1] * g2[0]


def _to_cam_frame(f: np.ndarray, psi: np.ndarray) -> np.ndarray:
    """R(-ψ) f: a follower-frame point in the cam's own frame."""
    c, s = np.cos(psi), np.sin(psi)
    return np.array([f[0] * c + f[1] * s, -f[0] * s + f[1] * c])


def _signed_radius(g1: np.ndarray, cross: np.ndarray, orientation: np.ndarray) -> np.ndarray:
    speed = np.hypot(g1[0], g1[1])
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(cross != 0.0, -speed**3 / cross * np.sign(orientation), np.inf)


@dataclass(frozen=True)
class Pitch:
    """A translating roller's (or a finger's) pitch-curve quantities at law angles ψ (rad)."""

    psi: np.ndarray
    R: np.ndarray  # R0 + L
    dL: np.ndarray
    pitch_radius: np.ndarray  # signed radius of curvature of the pitch curve (+ convex)
    speed: np.ndarray  # |dp/dψ| of the pitch curve (length/rad)
    pitch_point: np.ndarray  # (2, n) in the follower frame
    normal: np.ndarray  # (2, n) outward unit normal, follower frame


def pitch(law: CamSpec, base_radius: float, roller_radius: float, psi: np.ndarray) -> Pitch:
    """Pitch-curve quantities of a roller of radius r_r on a cam of base radius r_b (module doc)."""
    L, dL, ddL, _ = law_derivatives(law, psi)
    R = base_radius + roller_radius + L
    zeros = np.zeros_like(R)
    f = np.array([zeros, R])
    g1, _, cross = _frames(f, np.array([zeros, dL]), np.array([zeros, ddL]))
    speed = np.hypot(g1[0], g1[1])
    return Pitch(np.asarray(psi, dtype=float), R, dL, _signed_radius(g1, cross, np.ones_like(R)), speed, f,
                 _J(g1) / speed)


@dataclass(frozen=True)
class CamProfile:
    """The ground cam over one revolution of the law angle ψ (the cam's own frame)."""

    law_angle_deg: np.ndarray
    lift: np.ndarray
    x: np.ndarray
    y: np.ndarray
    radius: np.ndarray  # polar radius of the profile point
    polar_angle_deg: np.ndarray  # its polar angle in the cam frame, 0..360
    curvature_radius: np.ndarray  # signed radius of curvature (+ convex; inf at a flat spot)
    undercut: tuple[tuple[float, float], ...]  # law-angle intervals (deg) where the cam undercuts
    base_radius: float
    follower: str  # "flat" or "roller"

    @property
    def min_curvature_radius(self) -> float:
        """The smallest convex radius of curvature (a concave flank does not count), or the most negative."""
        rho = self.curvature_radius
        return float(rho.min())


def _crossings(psi_deg: np.ndarray, margin: np.ndarray) -> tuple[tuple[float, float], ...]:
    """Periodic intervals where ``margin`` < 0, their ends linearly interpolated between samples."""
    bad = margin < 0.0
    if not bad.any():
        return ()
    if bad.all():
        return ((0.0, 360.0),)
    n = len(psi_deg)
    step = 360.0 / n

    def edge(i: int) -> float:  # where margin crosses 0 between samples i and i + 1
        m0, m1 = margin[i], margin[(i + 1) % n]
        return float((psi_deg[i] + step * m0 / (m0 - m1)) % 360.0)

    starts = [i for i in range(n) if not bad[i] and bad[(i + 1) % n]]
    ends = [i for i in range(n) if bad[i] and not bad[(i + 1) % n]]
    result = []
    for s in starts:
        e = min(ends, key=lambda i: (i - s) % n)
        result.append((edge(s), edge(e)))
    return tuple(sorted(result))


def cam_profile(follower: FollowerSpec, law: CamSpec, points: int = 3600) -> CamProfile:
    """Profile, radius of curvature and undercut of the cam for a lift law and a follower (module doc)."""
    psi = np.linspace(0.0, 2.0 * math.pi, points, endpoint=False)
    L, dL, ddL, dddL = law_derivatives(law, psi)
    if follower.kind == FLAT:
        f = np.array([dL, follower.base_radius + L])
        g1, _, cross = _frames(f, np.array([ddL, dL]), np.array([dddL, ddL]))
        rho = _signed_radius(g1, cross, g1[0])
        point = f
        margin = rho
    else:
        p = pitch(law, follower.base_radius, follower.roller_radius, psi)
        point = p.pitch_point - follower.roller_radius * p.normal
        rho = p.pitch_radius - follower.roller_radius
        with np.errstate(divide="ignore"):
            margin = 1.0 - follower.roller_radius / p.pitch_radius  # < 0 where 0 < ρ_p < r_r
    xy = _to_cam_frame(point, psi)
    degrees = np.degrees(psi)
    return CamProfile(degrees, L, xy[0], xy[1], np.hypot(xy[0], xy[1]),
                      np.degrees(np.arctan2(xy[1], xy[0])) % 360.0, rho, _crossings(degrees, margin),
                      follower.base_radius, follower.kind)


# ----- finger follower ---------------------------------------------------------------------------

@dataclass(frozen=True)
class FingerGeometry:
    """Points of an end-pivot finger at the base circle (finger frame, y down; module doc)."""

    Q0: np.ndarray
    C: np.ndarray
    b: float
    R0: float

    @classmethod
    def of(cls, follower: FollowerSpec) -> FingerGeometry:
        finger = follower.finger
        assert finger is not None
        R0 = follower.base_radius + follower.roller_radius
        if abs(finger.cam_offset) >= R0:
            raise InputError("follower.cam_offset", finger.cam_offset,
                             f"smaller than the pitch radius base_radius + roller_radius = {R0:g}")
        if follower.arrangement == ROCKER:  # centre pivot: roller beyond the pivot, the cam below it
            Q0 = np.array([-finger.roller_arm, finger.roller_height])
            C = Q0 + np.array([-finger.cam_offset, math.sqrt(R0**2 - finger.cam_offset**2)])
        else:
            Q0 = np.array([finger.roller_arm, -finger.roller_height])
            C = Q0 + np.array([finger.cam_offset, -math.sqrt(R0**2 - finger.cam_offset**2)])
        return cls(Q0, C, finger.valve_arm, R0)

    def roller(self, phi: np.ndarray) -> np.ndarray:
        c, s = np.cos(phi), np.sin(phi)
        return np.array([self.Q0[0] * c - self.Q0[1] * s, self.Q0[0] * s + self.Q0[1] * c])

    def swing(self, Q: np.ndarray) -> np.ndarray:
        """δ: the angle of Q - C from the reference Q0 - C (rad)."""
        u = (self.Q0 - self.C)[:, None]
        d = Q - self.C[:, None]
        return np.arctan2(u[0] * d[1] - u[1] * d[0], u[0] * d[0] + u[1] * d[1])

    def valve_lift(self, phi: np.ndarray) -> np.ndarray:
        return self.b * np.sin(phi)


def finger_angle(follower: FollowerSpec, law: CamSpec, theta: np.ndarray) -> np.ndarray:
    """The finger's rotation φ (rad) at cam angles θ (rad), by Newton's method on F(φ, θ) = 0."""
    g = FingerGeometry.of(follower)
    theta = np.asarray(theta, dtype=float)
    phi = np.zeros_like(theta)
    for _ in range(NEWTON_STEPS):
        Q = g.roller(phi)
        d = Q - g.C[:, None]
        dist = np.hypot(d[0], d[1])
        delta = g.swing(Q)
        L, dL = law_derivatives(law, theta - delta)[:2]
        dQ = _J(Q)
        du = (d[0] * dQ[0] + d[1] * dQ[1]) / dist
        ddelta = (d[0] * dQ[1] - d[1] * dQ[0]) / dist**2
        F = dist - g.R0 - L
        slope = du + dL * ddelta
        if np.any(slope <= 0.0):
            raise InputError("follower.roller_arm", follower.finger.roller_arm,  # type: ignore[union-attr]  # a finger follower here (checked by the caller)
                             "a finger geometry whose roller moves away from the cam as it turns "
                             "(the contact condition has no unique root)")
        step = F / slope
        phi = phi - np.clip(step, -0.2, 0.2)
        if np.max(np.abs(step)) < NEWTON_TOLERANCE:
            break
    Q = g.roller(phi)
    d = Q - g.C[:, None]
    residual = np.hypot(d[0], d[1]) - g.R0 - law_derivatives(law, theta - g.swing(Q))[0]
    if np.max(np.abs(residual)) > 1e-9 * g.R0:
        raise InputError("follower", f"contact residual {np.max(np.abs(residual)):.3g}",
                         "a finger geometry on which the roller can follow the lift law")
    return phi


@dataclass(frozen=True)
class Contact:
    """Cam-follower contact quantities at cam angles θ (see :func:`contact`)."""

    cam_angle_deg: np.ndarray
    law_angle_deg: np.ndarray  # ψ: where on the law (and the profile) the follower touches
    lift: np.ndarray  # the law's lift there
    pressure_angle_deg: np.ndarray
    curvature_radius: np.ndarray  # the cam's, at the contact (+ convex)
    curvature: np.ndarray  # 1/R* of the line contact (cam and follower), 1/length
    force_factor: np.ndarray  # normal contact force per unit force of the model's cam contact
    entraining_per_omega: np.ndarray  # mean surface speed relative to the contact, length/rad (x ω)
    sliding_per_omega: np.ndarray  # cam surface speed minus follower surface speed, length/rad
    contact_travel: np.ndarray  # flat face: the contact point's offset from the follower's axis
    valve_lift: np.ndarray  # finger: the geometric valve lift; translating: the lift
    ratio: np.ndarray  # finger: dV/du (module doc); translating: 1
    model_lift: np.ndarray  # what the model's cam coordinate does (finger: V a/b; else the lift)
    #: the normal force's moment arm about the camshaft axis, signed: drive torque per unit normal force
    #: ((x - C) × n for a point x on the normal line, n the cam's outward normal; flat face: L')
    torque_arm: np.ndarray
    #: the tangent line's distance from the camshaft axis ((x - C)·n at the contact point x; flat face:
    #: r_b + L): drive torque per unit friction force at the contact
    tangent_arm: np.ndarray
    #: a finger's or rocker's: the cam's outward normal at the contact (2 x rows, finger frame) and the
    #: lever's rotation φ (rad); None for a translating follower
    normal: np.ndarray | None = None
    lever_angle: np.ndarray | None = None


def contact(follower: FollowerSpec, law: CamSpec, theta: np.ndarray) -> Contact:
    """Contact point, pressure angle, curvatures, speeds and force factor at cam angles θ (rad)."""
    theta = np.asarray(theta, dtype=float)
    ones = np.ones_like(theta)
    r_r = follower.roller_radius
    if follower.arrangement in LEVERS:
        g = FingerGeometry.of(follower)
        finger = follower.finger
        assert finger is not None
        phi = finger_angle(follower, law, theta)
        Q = g.roller(phi)
        d = Q - g.C[:, None]
        dist = np.hypot(d[0], d[1])
        delta = g.swing(Q)
        psi = theta - delta
        p = pitch(law, follower.base_radius, r_r, psi)
        e_r = d / dist
        n = (p.R * e_r + p.dL * _J(e_r)) / np.hypot(p.R, p.dL)  # outward normal, fixed frame
        dQ = _J(Q)
        du = (d[0] * dQ[0] + d[1] * dQ[1]) / dist
        ddelta = (d[0] * dQ[1] - d[1] * dQ[0]) / dist**2
        dphi = p.dL / (du + p.dL * ddelta)
        dpsi = 1.0 - ddelta * dphi
        dV = g.b * np.cos(phi)
        n_dQ = n[0] * dQ[0] + n[1] * dQ[1]
        speed_dir = dQ / np.hypot(dQ[0], dQ[1])
        alpha = np.arctan2(speed_dir[0] * n[1] - speed_dir[1] * n[0], speed_dir[0] * n[0] + speed_dir[1] * n[1])
        rho = p.pitch_radius - r_r
        V = g.valve_lift(phi)
        ratio_model = finger.roller_arm / finger.valve_arm
        arm = d[0] * n[1] - d[1] * n[0]
        return Contact(np.degrees(theta), np.degrees(psi), p.R - g.R0, np.degrees(alpha), rho,
                       1.0 / rho + 1.0 / r_r, ratio_model * dV / n_dQ,
                       np.abs(p.speed * rho / p.pitch_radius * dpsi), 0.0 * ones, np.full_like(theta, np.nan),
                       V, dV / du, V * ratio_model, arm, d[0] * n[0] + d[1] * n[1] - r_r, n, phi)
    L, dL, ddL, dddL = law_derivatives(law, theta)
    if follower.kind == FLAT:
        f = np.array([dL, follower.base_radius + L])
        g1, _, cross = _frames(f, np.array([ddL, dL]), np.array([dddL, ddL]))
        rho = _signed_radius(g1, cross, g1[0])
        with np.errstate(divide="ignore"):
            curvature = 1.0 / rho
        return Contact(np.degrees(theta), np.degrees(theta), L, 0.0 * ones, rho, curvature, ones,
                       0.5 * np.abs(rho + ddL), np.abs(follower.base_radius + L), dL, L, ones, L, dL,
                       follower.base_radius + L)
    p = pitch(law, follower.base_radius, r_r, theta)
    alpha = np.arctan2(p.dL, p.R)
    rho = p.pitch_radius - r_r
    return Contact(np.degrees(theta), np.degrees(theta), L, np.degrees(alpha), rho, 1.0 / rho + 1.0 / r_r,
                   1.0 / np.cos(alpha), np.abs(p.speed * rho / p.pitch_radius), 0.0 * ones,
                   np.full_like(theta, np.nan), L, ones, L, p.R * np.sin(alpha), p.R * np.cos(alpha) - r_r)


def model_lift(follower: FollowerSpec, law: CamSpec, theta: np.ndarray) -> np.ndarray:
    """The model's cam-coordinate lift at cam angles θ (rad): the law, or a finger's V a/b."""
    return contact(follower, law, theta).model_lift


# ----- reports (``vtool cam show``) ------------------------------------------------------------------

def shape_report(spec, points: int = 3600) -> dict:
    """The cam's shape for ``vtool cam show``: base radius, curvature, undercut, pressure angle, ratio."""
    follower = spec.follower
    law = spec.lift_law
    u = spec.unit_system.length
    profile = cam_profile(follower, law, points)
    c = contact(follower, law, np.linspace(0.0, 2.0 * math.pi, points, endpoint=False))
    rho = profile.curvature_radius
    convex = rho[rho > 0.0]
    report = {
        "follower": follower.kind, "arrangement": follower.arrangement, "length_unit": u,
        "base_radius": follower.base_radius, "roller_radius": follower.roller_radius,
        "largest_profile_radius": float(profile.radius.max()),
        "min_convex_curvature_radius": float(convex.min()) if convex.size else None,
        "min_curvature_radius": float(rho.min()),
        "undercut_deg": [list(pair) for pair in profile.undercut],
        "max_pressure_angle_deg": float(np.abs(c.pressure_angle_deg).max()),
        "max_valve_lift": float(c.valve_lift.max()),
    }
    if follower.kind == FLAT:
        report["max_contact_travel"] = float(np.nanmax(np.abs(c.contact_travel)))
        if follower.face_diameter is not None:
            report["face_radius"] = 0.5 * follower.face_diameter
    if follower.arrangement in LEVERS:
        lifting = c.lift > 1e-3 * max(float(c.lift.max()), 1e-300)
        report["ratio_min"] = float(c.ratio[lifting].min()) if lifting.any() else float(c.ratio.min())
        report["ratio_max"] = float(c.ratio.max())
        report["ratio_base_circle"] = float(c.ratio[np.argmin(c.lift)])
    return report


def shape_text(report: dict) -> str:
    """:func:`shape_report` as lines."""
    u = report["length_unit"]
    lines = [f"cam shape ({report['follower']} follower, {report['arrangement']}): base radius "
             f"{report['base_radius']:.5g} {u}, largest profile radius {report['largest_profile_radius']:.5g} {u}"]
    rho = report["min_convex_curvature_radius"]
    lines.append(f"  radius of curvature: smallest convex {'-' if rho is None else f'{rho:.5g}'} {u}, "
                 f"smallest {report['min_curvature_radius']:.5g} {u} (negative: concave or undercut)")
    if report["undercut_deg"]:
        spans = ", ".join(f"{a:.2f}..{b:.2f}" for a, b in report["undercut_deg"])
        lines.append(f"  warning: the cam undercuts (the follower cannot follow the law) at law angles {spans} deg")
    else:
        lines.append("  no undercut")
    lines.append(f"  largest pressure angle {report['max_pressure_angle_deg']:.4g} deg, "
                 f"largest valve lift {report['max_valve_lift']:.5g} {u}")
    if "max_contact_travel" in report:
        face = f" (face radius {report['face_radius']:.4g} {u})" if "face_radius" in report else ""
        lines.append(f"  contact travel on the flat face: up to {report['max_contact_travel']:.4g} {u}{face}")
    if "ratio_min" in report:
        lines.append(f"  finger ratio dV/du: {report['ratio_base_circle']:.5g} on the base circle, "
                     f"{report['ratio_min']:.5g} .. {report['ratio_max']:.5g} over the event")
    return "\n".join(lines)


def profile_csv_text(spec, step_deg: float = 0.5) -> str:
    """The ground profile for grinding: per law angle, lift, Cartesian and polar point, radius of curvature
    (cam frame: y along the follower at law angle 0, angles in degrees)."""
    follower, law = spec.follower, spec.lift_law
    u = spec.unit_system.length
    profile = cam_profile(follower, law, int(round(360.0 / step_deg)))
    header = (f"law_angle (deg),lift ({u}),x ({u}),y ({u}),polar_radius ({u}),polar_angle (deg),"
              f"curvature_radius ({u})")
    rows = np.column_stack([profile.law_angle_deg, profile.lift, profile.x, profile.y, profile.radius,
                            profile.polar_angle_deg, profile.curvature_radius])
    return header + "\n" + "\n".join(",".join(f"{v:.10g}" for v in row) for row in rows) + "\n"


def undercut_warning(follower: FollowerSpec, law: CamSpec) -> str | None:
    """One line when the cam undercuts (the follower cannot follow the law there), else None."""
    spans = cam_profile(follower, law).undercut
    if not spans:
        return None
    named = ", ".join(f"{a:.1f}..{b:.1f}" for a, b in spans[:4]) + (" ..." if len(spans) > 4 else "")
    return (f"follower: the cam undercuts at law angles {named} deg ({follower.kind} follower, base radius "
            f"{follower.base_radius:g}): the follower cannot follow the lift law there, and the contact stress "
            f"there is not computed (a larger base circle, a smaller roller or a gentler nose)")
