"""A helical compression valve spring from its data sheet: rate, mass, solid length, surge, stress, fatigue.

A :class:`SpringSpec` is what a spring's maker prints: round wire diameter
``d``, mean coil diameter ``D``, active and total coils, free, installed and
solid length, the material's shear modulus ``G``, density, tensile strength
``R_m`` and the shear fatigue limit, and optionally a pitch diagram (active
coils and free pitch per segment) or a measured force-length table. Every
quantity an engineer checks follows from it in closed form (lengths, forces,
stresses in the preset's units; one consistent unit system):

* rate ``k = G d^4 / (8 D^3 n_a)`` (a segment of ``n_i`` active coils:
  ``G d^4 / (8 D^3 n_i)``; segments in series give ``k``);
* mass of the active coils ``m_a = rho (pi d^2 / 4) pi D n_a`` (the whole wire
  with ``n_t``); the model's bar carries ``m_a`` (the dead end coils sit on
  the head and under the retainer: their mass is left out, a choice);
* solid length ``L_c = n_t d`` unless given (ground ends: the maker's figure);
* installed preload ``F_1 = k (L_0 - L_1)`` (or the table's force at ``L_1``);
* surge (fixed-fixed, the wave equation of the active coils):
  ``f_j = (j/2) sqrt(k / m_a)`` Hz, j = 1, 2, ...;
* shear stress ``tau = K 8 F D / (pi d^3)`` with the Bergstraesser factor
  ``K_B = (w + 0.5)/(w - 0.75)`` or Wahl's ``K_W = (4w - 1)/(4w - 4) + 0.615/w``,
  ``w = D/d`` (DIN EN 13906-1 uses Bergstraesser);
* fatigue safety factor, Goodman (our stated rule): with ``tau_m``, ``tau_a``
  the mean and amplitude of the corrected stress over a cycle, the fatigue
  limit ``tau_D`` (alternating shear at zero mean) and the ultimate shear
  strength ``tau_u = shear_ratio R_m`` (default 0.67, Shigley's ratio),
  ``S = 1 / (tau_a / tau_D + tau_m / tau_u)``;
* coil-bind margin: the smallest length reached minus ``L_c``, or with a
  pitch diagram a segment's smallest coil gap when smaller (:func:`coil_bind_margin`).

A pitch diagram gives the progressive force-length curve of the static
spring (:func:`pitch_force_length`): segment i closes (its coils touch) when
the force reaches ``k_i n_i (p_i - d) = G d^4 (p_i - d) / (8 D^3)``, so the
smallest pitch closes first; after that the spring is the remaining segments
in series (:func:`closing_forces` gives the order).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import overload

import numpy as np

SHEAR_RATIO = 0.67  # ultimate shear / tensile strength (Shigley); DIN EN 13906 gives 0.5 R_m as the static limit


@dataclass(frozen=True)
class SpringSpec:
    """One valve spring's data sheet (module doc); ``coordinate``: the model's coordinate of its moving end."""

    name: str
    wire_diameter: float
    coil_diameter: float  # mean
    active_coils: float
    total_coils: float
    free_length: float
    installed_length: float
    shear_modulus: float
    density: float
    tensile_strength: float
    coordinate: int
    fatigue_limit: float | None = None
    solid_length_given: float | None = None
    shear_ratio: float = SHEAR_RATIO
    segment_coils: tuple[float, ...] = ()  # pitch diagram: active coils per segment (fixed end first)
    segment_pitches: tuple[float, ...] = ()  # free pitch of each segment (length per coil)
    table_lengths: tuple[float, ...] = ()  # measured force-length table (decreasing lengths)
    table_forces: tuple[float, ...] = ()
    nodes: tuple[int, ...] = ()  # a pitch diagram's coordinates between its segments (fixed end first)
    contacts: tuple[str, ...] = ()  # a pitch diagram's coil-contact clearances, one per segment
    wire_height: float | None = None  # elliptic wire: its axis along the spring's (wire_diameter: the radial one)
    strength_law: tuple[float, float] | None = field(default=None, compare=False)  # (A, m): R_m = A / d^m (MPa, mm)

    # ----- closed forms -----
    @property
    def index(self) -> float:
        """Spring index w = D / d."""
        return self.coil_diameter / self.wire_diameter

    @property
    def rate(self) -> float:
        """G d^4 / (8 D^3 n_a); with a table, its slope at the installed length."""
        if self.table_lengths:
            return table_rate(self.table_lengths, self.table_forces, self.installed_length)
        return self.coil_rate(self.active_coils)

    def coil_rate(self, coils: float) -> float:
        """The rate of ``coils`` active coils: G d^4/(8 D^3 n), or for an elliptic wire 4 G J_t/(pi D^3 n)
        (:func:`elliptic_torsion_constant`; the round wire's J_t = pi d^4/32 gives the first)."""
        if self.wire_height is None:
            return coil_rate(self.shear_modulus, self.wire_diameter, self.coil_diameter, coils)
        J = elliptic_torsion_constant(0.5 * self.wire_diameter, 0.5 * self.wire_height)
        return 4.0 * self.shear_modulus * J / (math.pi * self.coil_diameter ** 3 * coils)

    def wire_mass(self, coils: float) -> float:
        """rho A pi D n, A = pi a b (round: pi d^2/4)."""
        if self.wire_height is None:
            return wire_mass(self.density, self.wire_diameter, self.coil_diameter, coils)
        return self.density * 0.25 * math.pi * self.wire_diameter * self.wire_height * math.pi * self.coil_diameter \
            * coils

    @property
    def axial_wire(self) -> float:
        """The wire's size along the spring's axis (coils touch across it): d, or an elliptic wire's height."""
        return self.wire_diameter if self.wire_height is None else self.wire_height

    @property
    def active_mass(self) -> float:
        return self.wire_mass(self.active_coils)

    @property
    def total_mass(self) -> float:
        return self.wire_mass(self.total_coils)

    @property
    def solid_length(self) -> float:
        return self.solid_length_given if self.solid_length_given is not None else self.total_coils * \
            self.axial_wire

    @property
    def preload(self) -> float:
        return float(self.force_at(self.installed_length))

    @property
    def rest_length(self) -> float:
        """The length at q = 0 of the model (the unloaded mechanism: the preload enters through the cam
        offset, so the installed spring sits at q = preload / rate): installed + preload / rate."""
        return self.installed_length + self.preload / self.model_rate

    @property
    def model_rate(self) -> float:
        """The model's (linear) rate: the bars' stiffness, segments in series."""
        if self.segment_coils:
            return 1.0 / float(np.sum(1.0 / segment_rates(self)))
        return self.rate

    @overload
    def force_at(self, length: float) -> float: ...
    @overload
    def force_at(self, length: np.ndarray) -> np.ndarray: ...
    def force_at(self, length: float | np.ndarray) -> float | np.ndarray:
        """The static force at a length: the table's (interpolated), else the pitch diagram's, else linear."""
        if self.table_lengths:
            lengths = np.asarray(self.table_lengths)[::-1]
            return np.interp(length, lengths, np.asarray(self.table_forces)[::-1])
        if self.segment_coils:
            return pitch_force_length(self, length)
        return self.rate * (self.free_length - np.asarray(length)) if isinstance(length, np.ndarray) else \
            self.rate * (self.free_length - length)

    def surge_frequencies(self, count: int = 3) -> list[float]:
        """Fixed-fixed surge frequencies f_j = (j/2) sqrt(k / m_a), Hz (time unit: s)."""
        return [0.5 * j * math.sqrt(self.rate / self.active_mass) for j in range(1, count + 1)]

    @overload
    def stress(self, force: float, factor: str = "bergstrasser") -> float: ...
    @overload
    def stress(self, force: np.ndarray, factor: str = "bergstrasser") -> np.ndarray: ...
    def stress(self, force: float | np.ndarray, factor: str = "bergstrasser") -> float | np.ndarray:
        """Corrected shear stress K 8 F D / (pi d^3); elliptic wire K F D / (pi a b^2), a >= b its semi-axes
        (:func:`elliptic_torsion_constant`), K on the index D / d of the radial axis d (our choice: DIN EN
        13906-1's factors are for round wire)."""
        if self.wire_height is None:
            return stress_factor(self.index, factor) * 8.0 * force * self.coil_diameter / \
                (math.pi * self.wire_diameter ** 3)
        a, b = 0.5 * max(self.wire_diameter, self.wire_height), 0.5 * min(self.wire_diameter, self.wire_height)
        return stress_factor(self.index, factor) * force * self.coil_diameter / (math.pi * a * b * b)

    def fatigue_factor(self, force_min: float, force_max: float) -> float | None:
        """Goodman safety factor of a cycle between two forces (module doc); None without a fatigue limit."""
        if self.fatigue_limit is None:
            return None
        return goodman(float(self.stress(force_min)), float(self.stress(force_max)), self.fatigue_limit,
                       self.shear_ratio * self.tensile_strength)


def coil_rate(G: float, d: float, D: float, n: float) -> float:
    return G * d ** 4 / (8.0 * D ** 3 * n)


def elliptic_torsion_constant(a: float, b: float) -> float:
    """Saint-Venant torsion constant of an ellipse of semi-axes a, b: J_t = pi a^3 b^3 / (a^2 + b^2)
    (Timoshenko and Goodier, Theory of Elasticity, 3rd ed. 1970, section 105); its largest shear stress,
    at the ends of the minor axis, is 2 T / (pi a b^2) for a >= b. a = b = d/2 gives pi d^4/32 and 16 T/(pi d^3)."""
    return math.pi * a ** 3 * b ** 3 / (a * a + b * b)


def power_law_strength(A: float, m: float, d: float) -> float:
    """Tensile strength R_m = A / d^m at wire diameter d (the form wire standards' tables follow)."""
    return A / d ** m


#: Minimum tensile strength (MPa) of oil-hardened and tempered valve spring wire EN 10270-2:2011 VDSiCrV
#: against wire diameter (mm, the upper end of each diameter band), as printed in voestalpine Boehler's
#: data sheet "Penthor 964" (edition 04/2016, "conforms to VDSiCrV according to EN 10270-2:2011"): bands
#: >1.00-1.30, >1.30-1.40, >1.40-1.60, >1.60-2.00, >2.00-2.50, >2.50-2.70 mm. We could not read the standard
#: itself; the sheet's bands below 1 mm (2230 MPa) are left out of the fit (valve spring wire is thicker).
VDSICRV_TABLE = ((1.30, 2230.0), (1.40, 2210.0), (1.60, 2210.0), (2.00, 2160.0), (2.50, 2100.0), (2.70, 2060.0))
STRENGTH_MATERIALS = {"VDSiCrV": VDSICRV_TABLE}


def fitted_strength_law(table: tuple[tuple[float, float], ...]) -> tuple[float, float]:
    """(A, m) of R_m = A / d^m (MPa, mm) fitted to a table of (d, R_m) by least squares on the logarithms."""
    d, rm = np.log([row[0] for row in table]), np.log([row[1] for row in table])
    slope, intercept = np.polyfit(d, rm, 1)
    return float(math.exp(intercept)), float(-slope)


def wire_mass(density: float, d: float, D: float, n: float) -> float:
    return density * 0.25 * math.pi * d * d * math.pi * D * n


def stress_factor(w: float, factor: str) -> float:
    """Bergstraesser (w + 0.5)/(w - 0.75) or Wahl (4w - 1)/(4w - 4) + 0.615/w."""
    if factor == "wahl":
        return (4.0 * w - 1.0) / (4.0 * w - 4.0) + 0.615 / w
    return (w + 0.5) / (w - 0.75)


def goodman(tau_min: float, tau_max: float, fatigue_limit: float, ultimate: float) -> float:
    """1 / (tau_a / tau_D + tau_m / tau_u)."""
    mean, amplitude = 0.5 * (tau_max + tau_min), 0.5 * (tau_max - tau_min)
    return 1.0 / (amplitude / fatigue_limit + mean / ultimate)


def table_rate(lengths: tuple[float, ...], forces: tuple[float, ...], at: float) -> float:
    """Slope -dF/dL of a force-length table at a length: the interval below it (the one a lift compresses
    into; at a table point, the next one down), the nearest end one outside."""
    L, F = np.asarray(lengths), np.asarray(forces)
    i = int(np.clip(np.searchsorted(-L, -at, side="right") - 1, 0, len(L) - 2))
    return float((F[i + 1] - F[i]) / (L[i] - L[i + 1]))


def segment_rates(s: SpringSpec) -> np.ndarray:
    return np.array([s.coil_rate(n) for n in s.segment_coils])


def closing_forces(s: SpringSpec) -> np.ndarray:
    """Force at which each pitch segment closes: G d^4 (p_i - d) / (8 D^3) (its coils touch)."""
    k = segment_rates(s)
    return k * np.asarray(s.segment_coils) * (np.asarray(s.segment_pitches) - s.axial_wire)


def pitch_force_length(s: SpringSpec, length: float | np.ndarray) -> float | np.ndarray:
    """Static force at a length of a spring with a pitch diagram (module doc): piecewise linear, progressive."""
    k = segment_rates(s)
    close = closing_forces(s)
    travel = np.asarray(s.free_length - np.asarray(length, dtype=float))
    # deflection at which each segment's force level is reached: sum over segments of min(F, close_i)/k_i
    levels = np.sort(close)
    deflections = np.array([np.sum(np.minimum(f, close) / k) for f in levels])
    force = np.empty_like(travel, dtype=float)
    flat = travel.ravel()
    out = force.ravel()
    for j, x in enumerate(flat):
        below = np.searchsorted(deflections, x)
        if below >= len(levels):  # every segment solid: the spring is a block
            out[j] = math.inf
            continue
        f0, x0 = (0.0, 0.0) if below == 0 else (levels[below - 1], deflections[below - 1])
        open_rate = 1.0 / np.sum(1.0 / k[close > f0]) if np.any(close > f0) else math.inf
        out[j] = f0 + open_rate * (x - x0)
    return float(force) if np.ndim(length) == 0 else force




# ----- a run's spring: lengths, forces, stresses (trace: vtool.solvers.trace.Trace, duck-typed) -----

def compression_sign(trace: object, coordinate: int) -> float:
    """+1 when the end coordinate's positive direction compresses the spring (it moves with the valve's
    lift), else -1: the sign of the correlation of q_end with the valve lift (-1 without a seat: the bar's
    own sense, ground at its first end)."""
    q = trace.coordinate(coordinate)  # type: ignore[attr-defined]  # a Trace, duck-typed: the model does not import the result module
    try:
        lift = trace.valve_lift()  # type: ignore[attr-defined]  # a Trace, duck-typed: the model does not import the result module
    except KeyError:
        return -1.0
    return 1.0 if float(np.dot(q, lift)) >= 0.0 else -1.0


def segment_gaps(s: SpringSpec, trace: object) -> np.ndarray:
    """Rows x segments: each pitch segment's coil gap n_i (p_i - d) minus its compression from the run
    (the model's segment bars are unloaded at q = 0); <= 0: that segment's coils touch (coil bind)."""
    sign = compression_sign(trace, s.coordinate)
    ends = (0, *s.nodes, s.coordinate)
    q = [np.zeros_like(trace.cam_angle, dtype=np.float64) if k == 0 else trace.coordinate(k)  # type: ignore[attr-defined]  # a Trace, duck-typed: the model does not import the result module
         for k in ends]
    free_gap = np.asarray(s.segment_coils) * (np.asarray(s.segment_pitches) - s.axial_wire)
    return np.column_stack([free_gap[i] - sign * (q[i + 1] - q[i]) for i in range(len(free_gap))])


def end_force(s: SpringSpec, trace: object, rows: slice = slice(None)) -> np.ndarray:
    """The spring's force on its moving end at each output row (compression positive).

    A pitch diagram: the top segment's bar, k_top times its compression, plus its coil contact's force
    (the run's own force: surge and coil clash included; the bar's consistent-mass inertia is left out).
    Otherwise the force-length law at the end's length from the run (one bar: its elastic force). The
    CSV column ``NAME_force`` and the quantity of ``vtool solve --orders NAME_force``; ``rows``: a slice."""
    q_end = trace.coordinate(s.coordinate, rows)  # type: ignore[attr-defined]  # a Trace, duck-typed: the model does not import the result module
    sign = compression_sign(trace, s.coordinate)
    if not s.segment_coils:
        return np.asarray(s.force_at(s.rest_length - sign * q_end), dtype=float)
    below = trace.coordinate(s.nodes[-1], rows) if s.nodes else np.zeros_like(q_end)  # type: ignore[attr-defined]  # a Trace, duck-typed: the model does not import the result module
    force = segment_rates(s)[-1] * sign * (q_end - below)
    if s.contacts:
        force = force + trace.force(s.contacts[-1], rows)  # type: ignore[attr-defined]  # a Trace, duck-typed: the model does not import the result module
    return np.asarray(force, dtype=float)


def force_quantity(s: SpringSpec) -> str:
    """The name of a spring's end force as a quantity and CSV column: ``valve_spring_force``."""
    return f"{s.name}_force"


def run_report(springs: tuple[SpringSpec, ...], trace: object) -> list[dict]:
    """Per spring: smallest length reached, coil-bind margin, forces and Bergstraesser stresses at installed,
    largest over the run and over the last cycle (min, max), the Goodman factor of the last cycle, surge."""
    angle = np.asarray(trace.cam_angle)  # type: ignore[attr-defined]  # a Trace, duck-typed: the model does not import the result module
    last = angle >= angle[-1] - 360.0 if angle.size else angle.astype(bool)
    u = trace.spec.unit_system  # type: ignore[attr-defined]  # a Trace, duck-typed: the model does not import the result module
    units = {"length_unit": u.length, "force_unit": u.force, "stress_unit": u.pressure,
             "stiffness_unit": u.stiffness, "mass_unit": u.mass, "frequency_unit": "Hz", "angle_unit": "deg"}
    result = []
    for s in springs:
        q = trace.coordinate(s.coordinate)  # type: ignore[attr-defined]  # a Trace, duck-typed: the model does not import the result module
        length = s.rest_length - compression_sign(trace, s.coordinate) * q
        force = end_force(s, trace)
        shortest = float(length.min())
        f_lo, f_hi = float(force[last].min()), float(force[last].max())
        result.append({
            "name": s.name, "rate": s.rate, "active_mass": s.active_mass, "preload": s.preload,
            "solid_length": s.solid_length, "min_length": shortest, "min_length_angle_deg": float(angle[np.argmin(length)]),
            "coil_bind_margin": coil_bind_margin((s,), trace),
            "coil_bind": bool(coil_bind_margin((s,), trace) <= 0.0),
            "installed_stress": float(s.stress(s.preload)),
            "installed_stress_wahl": float(s.stress(s.preload, "wahl")),
            "max_force": float(force.max()), "max_stress": float(s.stress(float(force.max()))),
            "max_stress_wahl": float(s.stress(float(force.max()), "wahl")),
            "last_cycle_force": [f_lo, f_hi],
            "last_cycle_stress": [float(s.stress(f_lo)), float(s.stress(f_hi))],
            "fatigue_factor": s.fatigue_factor(f_lo, f_hi) if np.isfinite(f_hi) else 0.0,
            "surge_hz": s.surge_frequencies(3),
        } | units | _clash(s, trace, angle))
    return result


def report_text(report: list[dict], units: object) -> list[str]:
    """Summary lines of :func:`run_report` (``units``: the preset's UnitSystem)."""
    L, F, P = units.length, units.force, units.pressure  # type: ignore[attr-defined]  # a UnitSystem, duck-typed (module doc)
    lines = ["", "valve springs (data sheet; tau = K 8 F D/(pi d^3), Bergstraesser K, Wahl in brackets):"]
    for r in report:
        fatigue = "n/a (no fatigue_limit)" if r["fatigue_factor"] is None else f"{r['fatigue_factor']:.3f}"
        lines += [
            f"  {r['name']}: rate {r['rate']:.5g} {units.stiffness}, preload {r['preload']:.5g} {F}, "  # type: ignore[attr-defined]  # a UnitSystem, duck-typed (module doc)
            f"surge {', '.join(f'{f:.1f}' for f in r['surge_hz'])} Hz",
            f"    stress installed {r['installed_stress']:.5g} ({r['installed_stress_wahl']:.5g}) {P}, largest "
            f"{r['max_stress']:.5g} ({r['max_stress_wahl']:.5g}) {P} at force {r['max_force']:.5g} {F}",
            f"    last cycle force {r['last_cycle_force'][0]:.5g} .. {r['last_cycle_force'][1]:.5g} {F}, "
            f"Goodman fatigue factor {fatigue}",
            f"    shortest length {r['min_length']:.5g} {L} at {r['min_length_angle_deg']:.1f} deg, solid "
            f"{r['solid_length']:.5g} {L}; coil-bind margin {r['coil_bind_margin']:.4g} {L}"
            + ("  COIL BIND" if r["coil_bind"] else ""),
        ]
        if "segment_first_touch_deg" in r:
            touches = ", ".join(f"{i + 1}: " + ("-" if a is None else f"{a:.1f} deg")
                                for i, a in enumerate(r["segment_first_touch_deg"]))
            lines.append(f"    pitch segments, coils first touching (smallest gap "
                         f"{', '.join(f'{g:.3g}' for g in r['segment_min_gap'])} {L}): {touches}")
            if r["first_coil_bind_deg"] is not None and "coil_contact_peak_force" in r:
                lines.append(f"    first coil clash at {r['first_coil_bind_deg']:.1f} deg; peak coil contact force "
                             f"{r['coil_contact_peak_force']:.5g} {F} (per segment "
                             f"{', '.join(f'{f:.4g}' for f in r['segment_contact_peak_force'])} {F})")
            elif r["first_coil_bind_deg"] is not None:
                lines.append(f"    first coil clash at {r['first_coil_bind_deg']:.1f} deg: the model's segments do "
                             "not stop there (coil_contact = \"none\": no coil-contact force); the response after it "
                             "is not to be trusted")
    return lines


def _clash(s: SpringSpec, trace: object, angle: np.ndarray) -> dict:
    """A pitch diagram's segments: the first angle each segment's coils touch (None: never), the first
    coil-bind angle of the spring, the smallest gap per segment."""
    if not s.segment_coils or not angle.size:
        return {}
    gaps = segment_gaps(s, trace)
    first: list[float | None] = []
    for i in range(gaps.shape[1]):
        touching = np.flatnonzero(gaps[:, i] <= 0.0)
        first.append(float(angle[touching[0]]) if touching.size else None)
    result: dict = {"segment_min_gap": gaps.min(axis=0).tolist()}
    if s.contacts:  # the coil contacts' own events and forces (the model stops the coils there)
        names = [c.name for c in trace.spec.clearances]  # type: ignore[attr-defined]  # a Trace, duck-typed: the model does not import the result module
        closed = {name: [e.cam_angle for e in trace.events if e.clearance == name and e.kind == "closed"]  # type: ignore[attr-defined]  # a Trace, duck-typed: the model does not import the result module
                  for name in s.contacts}
        first = [min(closed[name]) if closed[name] else None for name in s.contacts]
        peaks = [float(trace.peak_force[names.index(name)]) for name in s.contacts]  # type: ignore[attr-defined]  # a Trace, duck-typed: the model does not import the result module
        result |= {"coil_contacts": list(s.contacts), "segment_contact_peak_force": peaks,
                   "coil_contact_peak_force": max(peaks)}
    seen = [a for a in first if a is not None]
    return result | {"segment_first_touch_deg": first, "first_coil_bind_deg": min(seen) if seen else None}


def coil_bind_margin(springs: tuple[SpringSpec, ...], trace: object, rows: np.ndarray | None = None) -> float:
    """The smallest coil-bind margin over the springs and ``rows`` (default all): the shortest length reached
    minus the solid length, or a pitch segment's smallest coil gap when smaller (<= 0: coils touch)."""
    margins = []
    for s in springs:
        q = trace.coordinate(s.coordinate)  # type: ignore[attr-defined]  # a Trace, duck-typed: the model does not import the result module
        length = s.rest_length - compression_sign(trace, s.coordinate) * q
        chosen = slice(None) if rows is None else rows
        if np.size(length[chosen]) == 0:
            continue
        margins.append(float(length[chosen].min()) - s.solid_length)
        if s.segment_coils:
            margins.append(float(segment_gaps(s, trace)[chosen].min()))
    return min(margins) if margins else math.nan


def surge_table(springs: tuple[SpringSpec, ...], rpm: float, count: int = 3) -> list[dict]:
    """Per spring: its fixed-fixed surge frequencies (Hz) and their ratio to the cam frequency rpm/60
    (the cam order a surge mode sits at: a lift harmonic of that order excites it)."""
    cam_hz = rpm / 60.0
    return [{"spring": s.name, "rate": s.rate, "active_mass": s.active_mass, "surge_hz": s.surge_frequencies(count),
             "cam_hz": cam_hz, "surge_order": [f / cam_hz for f in s.surge_frequencies(count)]} for s in springs]


def surge_text(table: list[dict], units: object) -> list[str]:
    """Lines of :func:`surge_table` (``vtool modes``)."""
    if not table:
        return []
    lines = ["", f"valve spring surge (fixed-fixed, (j/2) sqrt(k/m_a)), cam frequency {table[0]['cam_hz']:.4g} Hz:"]
    for row in table:
        lines.append(f"  {row['spring']}: rate {row['rate']:.5g} {units.stiffness}, active mass "  # type: ignore[attr-defined]  # a UnitSystem, duck-typed (module doc)
                     f"{row['active_mass']:.4g} {units.mass}: "  # type: ignore[attr-defined]  # a UnitSystem, duck-typed (module doc)
                     + ", ".join(f"{f:.1f} Hz (order {o:.1f})" for f, o in zip(row["surge_hz"], row["surge_order"],
                                                                              strict=True)))
    return lines
