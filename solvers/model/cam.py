"""The cam's lift as a periodic Fourier series: harmonic cams, lift tables, fit reports.

The cam coordinate moves as q_cam(t) = base + L(θ), θ = ωt in rad from the
preset's angle zero, with the lift

    L(θ) = c0 + Σ_{k=1..K} ( a_k cos kθ + b_k sin kθ )

(:mod:`vtool.solvers.model.sources`). The thesis' harmonic cam is L = A + A sin θ
(c0 = A, b_1 = A). A lift table (θ_i, L_i), any spacing over one revolution,
is fitted by linear least squares on the samples:

    min ‖ Φ x - L ‖₂,   Φ_i = [1, cos θ_i, sin θ_i, ..., cos Kθ_i, sin Kθ_i]

On a table sampled at N equal steps this is the truncated discrete Fourier
series; a table that is itself a trigonometric polynomial of degree <= K
comes back exactly. One QR factorization Φ = QR of the widest basis gives the
fit of every K at once (the leading columns of Q span the basis of the first
K harmonics), so ``tolerance`` picks the fewest harmonics whose largest
residual at the samples is within it.

Derivatives with respect to θ (length/rad^n) follow term by term; at a cam
speed ω they are velocity, acceleration and jerk times ω, ω², ω³. Junctions
where the table's acceleration jumps (a ramp meeting a flank) are found from
the table itself, not the fit: the second divided differences
a_i = 2 [ (L_{i+1} - L_i)/h_+ - (L_i - L_{i-1})/h_- ] / (h_+ + h_-) of a
smooth table change by O(h) from sample to sample; a jump J changes them by
about J within one or two samples, standing out against its neighbours (a
jump is flagged above 2 % of the table's 90th-percentile |acceleration| and
3 times the change two samples either side). A kink in the lift (a velocity
jump) shows as a spike: up then down at one sample. A coarse table (a few
points per lobe) changes by O(1) from sample to sample even where it is
smooth, so a flagged change must also survive in the table less its fit of
(n - 1) // 4 harmonics (half of what n points fix, so at least four samples
per wavelength): a smooth table, such as a 7-point sine, is such a series and
leaves nothing, while a jump is wider in frequency than any fit that the
samples resolve and stays. Tables are assumed smooth between junctions:
lifts rounded to few digits can raise false flags.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from vtool.errors import InputError
from vtool.solvers.model.spec import CamSpec

HARMONIC = "harmonic"
TABLE = "table"
MAX_HARMONICS = 400
MAX_POINTS = 10_000
QR_ENTRIES = 2_000_000  # the least-squares matrix of an unequally spaced table, at most
JUMP_FRACTION = 0.02  # a jump must exceed this share of the table's typical acceleration (90th pct) ...
JUMP_ISOLATION = 3.0  # ... and this many times the change two samples either side


@dataclass(frozen=True)
class LiftFit:
    """A lift table's Fourier fit: coefficients and its error at the samples (length units)."""

    c0: float
    a: np.ndarray
    b: np.ndarray
    max_error: float
    rms_error: float

    @property
    def harmonics(self) -> int:
        return len(self.a)


@dataclass(frozen=True)
class Junction:
    """A place where the table's acceleration d²L/dθ² jumps (length/rad²), or its velocity does."""

    angle_deg: float
    jump: float
    before: float
    after: float
    kind: str = "acceleration"  # or "velocity": a kink in the lift (an acceleration spike)


def normalize_table(angles_deg: list[float], lifts: list[float], field: str, unit: str) -> tuple[np.ndarray, np.ndarray]:
    """Validate a lift table: >= 3 points, angles strictly increasing within one revolution.

    A closing point at first angle + 360 deg repeating the first lift is dropped.
    """
    theta = np.asarray(angles_deg, dtype=float)
    lift = np.asarray(lifts, dtype=float)
    if theta.shape != lift.shape:
        raise InputError(f"{field}.lifts", f"{lift.size} values", f"as many lifts as angles ({theta.size})", unit)
    if theta.size >= 2 and abs(theta[-1] - theta[0] - 360.0) < 1e-9:
        if abs(lift[-1] - lift[0]) > 1e-9 * max(1.0, float(np.abs(lift).max())):
            raise InputError(f"{field}.lifts", float(lift[-1]),
                             f"the lift at {theta[0]:g} deg ({lift[0]:g}): a cam is periodic", unit)
        theta, lift = theta[:-1], lift[:-1]
    if not 3 <= theta.size <= MAX_POINTS:
        raise InputError(f"{field}.angles", f"{theta.size} points", f"3..{MAX_POINTS} points over one revolution",
                         "deg")
    if not (np.all(np.isfinite(theta)) and np.all(np.isfinite(lift))):
        raise InputError(f"{field}.angles", "non-finite values", "finite angles and lifts", "deg")
    if np.any(np.diff(theta) <= 0.0) or theta[-1] - theta[0] >= 360.0:
        raise InputError(f"{field}.angles", f"{theta[0]:g}..{theta[-1]:g}",
                         "strictly increasing angles spanning less than 360", "deg")
    return theta, lift


def _basis(theta_rad: np.ndarray, harmonics: int) -> np.ndarray:
    """Φ with columns 1, cos θ, sin θ, cos 2θ, sin 2θ, ..."""
    columns = [np.ones_like(theta_rad)]
    for k in range(1, harmonics + 1):
        columns += [np.cos(k * theta_rad), np.sin(k * theta_rad)]
    return np.column_stack(columns)


def max_harmonics(n_points: int) -> int:
    """The most harmonics a table of n points can determine (2K + 1 <= n)."""
    return min((n_points - 1) // 2, MAX_HARMONICS)


def _uniform_fit(theta: np.ndarray, lift: np.ndarray, K: int) -> tuple[float, np.ndarray, np.ndarray]:
    """The least-squares fit on N equal steps: the truncated DFT, shifted to start at θ_0."""
    N = theta.size
    C = 2.0 * np.fft.rfft(lift)[: K + 1] / N
    D = C[1:] * np.exp(-1j * np.arange(1, K + 1) * theta[0])
    return float(C[0].real / 2.0), D.real.copy(), -D.imag.copy()


def _residual(theta: np.ndarray, lift: np.ndarray, c0: float, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return lift - derivatives(c0, a, b, theta)[0]


def fit_table(angles_deg: np.ndarray, lifts: np.ndarray, harmonics: int | None = None,
              tolerance: float | None = None, field: str = "cam", unit: str = "") -> LiftFit:
    """Least-squares Fourier fit of a lift table (see module doc).

    Give ``harmonics`` (K) or ``tolerance`` (the largest residual allowed at
    the samples, length units; the fewest K that meet it are used). Equal
    steps use the FFT; other spacings a QR factorization whose size is
    bounded (at most :data:`QR_ENTRIES` matrix entries), so any table fits in
    seconds.
    """
    theta = np.radians(np.asarray(angles_deg, dtype=float))
    lift = np.asarray(lifts, dtype=float)
    N = theta.size
    uniform = bool(np.allclose(np.diff(theta), 2 * math.pi / N, rtol=0.0, atol=1e-9))
    top = max_harmonics(N) if uniform else min(max_harmonics(N), max(1, (QR_ENTRIES // N - 1) // 2))
    if harmonics is not None and not 1 <= harmonics <= top:
        raise InputError(f"{field}.harmonics", harmonics,
                         f"an integer in 1..{top} (what a table of {N} points with this spacing fixes)")
    widest = harmonics if harmonics is not None else top
    if uniform:
        c0, a, b = _uniform_fit(theta, lift, widest)
    else:
        Q, R = np.linalg.qr(_basis(theta, widest))
        diagonal = np.abs(np.diag(R))
        bad = np.nonzero(diagonal < 1e-10 * diagonal.max())[0]
        usable = widest if bad.size == 0 else (int(bad[0]) - 1) // 2
        if harmonics is not None and usable < harmonics:
            raise InputError(f"{field}.harmonics", harmonics,
                             f"<= {max(usable, 1)}: the table's spacing cannot tell more apart (ill-conditioned)")
        widest = max(usable, 1)
        x = np.linalg.solve(R[: 2 * widest + 1, : 2 * widest + 1], (Q.T @ lift)[: 2 * widest + 1])
        c0, a, b = float(x[0]), x[1::2].copy(), x[2::2].copy()
    if harmonics is None:
        # nested least squares: the fit of K harmonics is the widest one's first terms only on equal
        # steps; otherwise refit each K (cheap: K is small where most tables stop)
        fitted = np.full(N, c0)
        projection = None if uniform else Q.T @ lift
        for K in range(1, widest + 1):
            if uniform:
                fitted += a[K - 1] * np.cos(K * theta) + b[K - 1] * np.sin(K * theta)
                error = np.abs(lift - fitted).max()
            else:
                assert projection is not None  # (made above when the angles are not uniform)
                x = np.linalg.solve(R[: 2 * K + 1, : 2 * K + 1], projection[: 2 * K + 1])
                error = np.abs(lift - Q[:, : 2 * K + 1] @ projection[: 2 * K + 1]).max()
            if error <= tolerance:
                if uniform:
                    a, b = a[:K].copy(), b[:K].copy()
                else:
                    c0, a, b = float(x[0]), x[1::2].copy(), x[2::2].copy()
                break
        else:
            raise InputError(f"{field}.tolerance", tolerance,
                             f">= {error:.3g} (the best fit with {widest} harmonics; or give more points)", unit)
    residual = _residual(theta, lift, c0, a, b)
    return LiftFit(c0, a, b, float(np.abs(residual).max()), float(np.sqrt(np.mean(residual**2))))


@lru_cache(maxsize=64)
def cam_fit(cam: CamSpec) -> LiftFit:
    """The fit of a cam (harmonic: exact, one term)."""
    if cam.profile == HARMONIC:
        return LiftFit(cam.amplitude, np.zeros(1), np.array([cam.amplitude]), 0.0, 0.0)
    return fit_table(np.asarray(cam.angles), np.asarray(cam.lifts), cam.harmonics, cam.tolerance)


def lift_series(cam: CamSpec) -> tuple[float, np.ndarray, np.ndarray]:
    """(c0, a[K], b[K]) of the cam's lift L(θ) = c0 + Σ a_k cos kθ + b_k sin kθ, for every profile."""
    fit = cam_fit(cam)
    return fit.c0, fit.a.copy(), fit.b.copy()


def derivatives(c0: float, a: np.ndarray, b: np.ndarray, theta_rad: np.ndarray) -> np.ndarray:
    """Rows: L, dL/dθ, d²L/dθ², d³L/dθ³ at θ (length/rad^n)."""
    theta = np.asarray(theta_rad, dtype=float)
    out = np.zeros((4, theta.size))
    out[0] = c0
    for k in range(1, len(a) + 1):
        c, s = np.cos(k * theta), np.sin(k * theta)
        ak, bk = a[k - 1], b[k - 1]
        out[0] += ak * c + bk * s
        out[1] += k * (-ak * s + bk * c)
        out[2] += -(k**2) * (ak * c + bk * s)
        out[3] += k**3 * (ak * s - bk * c)
    return out


def spectrum(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per harmonic k = 1..K: lift amplitude |c_k| and acceleration amplitude k²|c_k| (length/rad²)."""
    amplitude = np.hypot(a, b)
    k = np.arange(1, len(a) + 1)
    return amplitude, k**2 * amplitude


def highest_harmonic(a: np.ndarray, b: np.ndarray, fraction: float) -> int:
    """The highest k whose acceleration amplitude is at least ``fraction`` of the largest one."""
    _, acc = spectrum(a, b)
    if acc.max() == 0.0:
        return 0
    return int(np.nonzero(acc >= fraction * acc.max())[0].max()) + 1


WIDE_FIT = 128


def harmonic_that_matters(cam: CamSpec) -> int:
    """The highest harmonic whose acceleration amplitude is >= 1 % of the largest.

    A table cam is judged on its widest fit (up to 128 harmonics), not on the
    preset's truncated one.
    """
    if cam.profile == HARMONIC:
        return 1
    angles, lifts = np.asarray(cam.angles), np.asarray(cam.lifts)
    wide = fit_table(angles, lifts, min(max_harmonics(len(angles)), WIDE_FIT))
    return highest_harmonic(wide.a, wide.b, MATTERS)


def table_acceleration(angles_deg: np.ndarray, lifts: np.ndarray) -> np.ndarray:
    """Second divided differences of a periodic table at its samples (length/rad²)."""
    theta = np.radians(np.asarray(angles_deg, dtype=float))
    L = np.asarray(lifts, dtype=float)
    h_next = np.diff(np.append(theta, theta[0] + 2 * math.pi))
    h_prev = np.roll(h_next, 1)
    slope_next = (np.roll(L, -1) - L) / h_next
    slope_prev = (L - np.roll(L, 1)) / h_prev
    return 2.0 * (slope_next - slope_prev) / (h_next + h_prev)


def acceleration_jumps(angles_deg: np.ndarray, lifts: np.ndarray) -> list[Junction]:
    """Junctions where the table's acceleration jumps (see module doc), in table order."""
    theta = np.asarray(angles_deg, dtype=float)
    acc = table_acceleration(theta, lifts)
    n = acc.size
    if n < 6:
        return []
    change = np.roll(acc, -1) - acc  # change[i]: from sample i to i + 1
    size = np.abs(change)
    scale = float(np.percentile(np.abs(acc), 90))  # robust: kinks (spikes) do not set the scale
    if scale == 0.0:
        scale = float(np.abs(acc).max())
    if scale == 0.0:
        return []
    neighbours = np.maximum(np.roll(size, 2), np.roll(size, -2))
    flagged = (size > JUMP_FRACTION * scale) & (size > JUMP_ISOLATION * neighbours)
    if flagged.any():  # a flag must not be explained by a series the samples resolve (module doc)
        smooth = fit_table(theta, lifts, max(1, max_harmonics(n) // 2))
        rough = table_acceleration(theta, _residual(np.radians(theta), np.asarray(lifts, dtype=float),
                                                    smooth.c0, smooth.a, smooth.b))
        rough_size = np.abs(np.roll(rough, -1) - rough)
    junctions = []
    done: set[int] = set()
    for i in np.nonzero(flagged)[0]:
        if i in done:
            continue
        group = [int(i)]
        kind = "acceleration"
        if flagged[(i + 1) % n]:
            group.append(int((i + 1) % n))
            if np.sign(change[(i + 1) % n]) != np.sign(change[i]):
                kind = "velocity"  # an isolated spike: the slope itself jumps at the shared sample
        done.update(group)
        if rough_size[group].max() <= JUMP_FRACTION * scale:
            continue
        first = group[0]
        before, after = acc[(first - 1) % n], acc[(group[-1] + 2) % n]  # just outside the stencils
        step = theta[(first + 1) % n] - theta[first]
        if len(group) == 2:
            angle = theta[(first + 1) % n]  # the junction sits on the shared sample
        else:
            angle = theta[first] + 0.5 * (step if step > 0 else step + 360.0)
        junctions.append(Junction(float(angle % 360.0), float(after - before), float(before), float(after), kind))
    return sorted(junctions, key=lambda j: j.angle_deg)


MAX_NAMED = 6  # junction angles a warning names before "and N more"


def junction_warning(angles_deg: np.ndarray, lifts: np.ndarray, field: str = "cam") -> str | None:
    """One line naming the angles where a lift table's acceleration jumps, or None.

    Loading a preset with such a table warns with it (``vtool solve``, the
    TUI, every command), not only ``vtool cam show``, which prints the sizes.
    """
    junctions = acceleration_jumps(np.asarray(angles_deg, dtype=float), np.asarray(lifts, dtype=float))
    if not junctions:
        return None
    named = [f"{j.angle_deg:g} deg" + ("" if j.kind == "acceleration" else " (velocity kink)")
             for j in junctions[:MAX_NAMED]]
    more = f" and {len(junctions) - MAX_NAMED} more" if len(junctions) > MAX_NAMED else ""
    return (f"{field}: the lift table's acceleration jumps at {', '.join(named)}{more} (a ramp/flank "
            f"junction?): its Fourier series rings there; `vtool cam show` gives the sizes")


MATTERS = 0.01  # a harmonic matters when its acceleration amplitude is >= 1 % of the largest


def cam_report(spec, points: int = 3600, top: int = 8) -> dict:
    """What ``vtool cam show`` prints: fit, extremes at the preset's speed, spectrum, junctions.

    Derivatives are of the fitted series (what the solver sees); at the run's
    ω they are scaled by ω, ω², ω³ to velocity, acceleration and jerk.
    """
    units = spec.unit_system
    cam = spec.cam
    fit = cam_fit(cam)
    omega = spec.run.omega
    theta = np.linspace(0.0, 2 * math.pi, points, endpoint=False)
    L, v, acc, jerk = derivatives(fit.c0, fit.a, fit.b, theta)
    lift_amplitude, acc_amplitude = spectrum(fit.a, fit.b)
    order = np.argsort(acc_amplitude)[::-1][:top]
    per_s = {"velocity": units.velocity, "acceleration": units.acceleration,
             "jerk": f"{units.length}/s^3"}
    report: dict = {
        "title": spec.title, "profile": cam.profile, "harmonics": fit.harmonics,
        "length_unit": units.length, "rpm": spec.run.rpm,
        "fit_max_error": fit.max_error, "fit_rms_error": fit.rms_error,
        "table_points": len(cam.angles),
        "lift_max": float(L.max()), "lift_min": float(L.min()),
        "extremes": {}, "spectrum": [], "junctions": [],
        "highest_harmonic": harmonic_that_matters(cam),
    }
    for name, values, power in (("velocity", v, 1), ("acceleration", acc, 2), ("jerk", jerk, 3)):
        report["extremes"][name] = {
            "min": float(values.min() * omega**power), "max": float(values.max() * omega**power),
            "unit": per_s[name], "per_rad_unit": f"{units.length}/rad^{power}",
            "min_per_rad": float(values.min()), "max_per_rad": float(values.max())}
    for k in sorted(order + 1):
        report["spectrum"].append({
            "harmonic": int(k), "frequency_hz": k * spec.run.rpm / 60.0,
            "lift_amplitude": float(lift_amplitude[k - 1]),
            "acceleration_amplitude": float(acc_amplitude[k - 1] * omega**2)})
    if cam.profile != HARMONIC:
        for j in acceleration_jumps(np.asarray(cam.angles), np.asarray(cam.lifts)):
            report["junctions"].append({"angle_deg": j.angle_deg, "kind": j.kind, "jump_per_rad2": j.jump,
                                        "jump": j.jump * omega**2, "unit": units.acceleration})
    return report


def report_text(report: dict) -> str:
    """The report as the lines ``vtool cam show`` prints."""
    u = report["length_unit"]
    lines = [report["title"],
             f"cam: {report['profile']}, {report['harmonics']} harmonic(s)"
             + (f" fitted to {report['table_points']} table points: largest error "
                f"{report['fit_max_error']:.3g} {u}, rms {report['fit_rms_error']:.3g} {u}"
                if report["profile"] != HARMONIC else " (exact)"),
             f"lift {report['lift_min']:.6g} .. {report['lift_max']:.6g} {u}"
             f"   at {report['rpm']:g} rpm:"]
    for name, e in report["extremes"].items():
        lines.append(f"  {name:<12} {e['min']:>13.5g} .. {e['max']:<13.5g} {e['unit']:<10}"
                     f" ({e['min_per_rad']:.4g} .. {e['max_per_rad']:.4g} {e['per_rad_unit']})")
    lines.append(f"highest harmonic that matters (acceleration >= {MATTERS:.0%} of the largest): "
                 f"{report['highest_harmonic']}")
    lines.append(f"  {'k':>4} {'f (Hz)':>10} {'lift amp (' + u + ')':>16} {'accel amp (' + u + '/s^2)':>22}")
    for row in report["spectrum"]:
        lines.append(f"  {row['harmonic']:>4} {row['frequency_hz']:>10.5g} {row['lift_amplitude']:>16.5g}"
                     f" {row['acceleration_amplitude']:>22.5g}")
    for j in report["junctions"]:
        what = "acceleration jumps by" if j["kind"] == "acceleration" else "velocity jumps (a kink)"
        size = f" {j['jump']:.4g} {j['unit']}" if j["kind"] == "acceleration" else ""
        lines.append(f"warning: the table's {what}{size} at {j['angle_deg']:g} deg (a ramp/flank "
                     f"junction?): its Fourier series rings there")
    return "\n".join(lines)


def table_start(spec, harmonic, omega: float, layer):
    """The static start of a table cam, from the harmonic rule's start ``harmonic``.

    :func:`vtool.solvers.model.initial.static_start` places the harmonic cam at
    XZERO = A + base; its deflection shape per unit follower displacement,
    q / XZERO, and base = XZERO - A carry over. The table cam starts at
    q_cam(0) = base + L(0), moving at L'(0) ω with acceleration L''(0) ω²;
    the cam's series constant ("cam offset") is base + c0, so that
    q_cam = base + L(ωt).
    """
    from vtool.solvers.model.initial import StaticStart, cam_clearance, start_state
    from vtool.solvers.model.spec import QUASI_STATIC_START

    base = harmonic.cam_offset - spec.cam.amplitude
    c0, a, b = lift_series(spec.cam)
    L, dL, ddL, _ = derivatives(c0, a, b, np.zeros(1))[:, 0]
    shape = harmonic.q / harmonic.cam_offset
    x0 = base + L
    q, shape, closed, force = start_state(spec, layer, x0, shape)  # (a spring's coils closed at the start)
    if spec.initial.velocities == QUASI_STATIC_START:
        qd, qdd = shape * dL * omega, shape * ddL * omega**2
    else:  # the thesis' INITAL: the follower moves with the cam, everything else at rest
        follower = cam_clearance(spec).ahead
        qd, qdd = np.zeros_like(shape), np.zeros_like(shape)
        qd[follower - 1], qdd[follower - 1] = dL * omega, ddL * omega**2
    return StaticStart(cam_offset=base + c0,
                       follower_force=harmonic.follower_stiffness * x0 if force is None else force,
                       follower_stiffness=harmonic.follower_stiffness, q=q, qd=qd, qdd=qdd, closed=closed)
