"""Measured cam lift: scans in mm, inches or thousandths, against cam or crank degrees, of tappet or valve lift.

A measured lift table is read from a CSV (``[cam] lift_table``) or from a
polyline script of ``angle,lift`` points (``[cam] polyline``: the points a
CAD ``PLINE`` command takes, separated by spaces or new lines; command words
are skipped). A ``[cam.scan]`` table says what the numbers are::

    [cam.scan]
    lift_unit = "thou"       # mm | in | thou (0.001 in) | m; default: the preset's length unit
    angle = "crank"          # cam (default) | crank: 2 crank degrees per cam degree (four-stroke)
    lift_of = "valve"        # tappet (default) | valve: divided by rocker_ratio
    rocker_ratio = 1.5       # valve lift per tappet lift (with lift_of = "valve")
    smoothing = "fourier"    # none (default) | fourier | spline (below)
    noise = 0.1              # optional: the scan's noise rms, in lift_unit; default: estimated
    peak_tolerance = 0.5     # optional, in lift_unit; default: 4 x the noise rms

The loader converts to cam degrees and tappet lift in the preset's length
unit and says what it did, one ``note:`` line per conversion
(:class:`vtool.errors.PresetNote`), e.g.
``note: cam.lift_table: lift in thou converted to in (x 0.001); crank degrees
halved to cam degrees; valve lift divided by the rocker ratio 1.5 to tappet lift``.

Smoothing (``smoothing = "fourier"``), a truncated Fourier series whose
cut-off comes from the noise:

1. The scan must have equal angle steps; a scan that covers less than a
   revolution is extended with base-circle lift (0) to 360 deg (said).
2. The lift's DFT ``X_k`` (N points) is split into signal and noise: white
   noise of rms ``s`` has ``E|X_k|^2 = N s^2``, flat in ``k``, while a cam's
   harmonics fall off fast. ``s`` is estimated from the upper half of the
   harmonics, ``s^2 = median |X_k|^2 / (N ln 2)`` (the median of an
   exponential variable is ln 2 times its mean), unless ``noise`` is given.
3. The cut-off ``K`` is the highest harmonic whose power exceeds
   ``tau N s^2`` with ``tau = ln(M / 0.01)`` (M harmonics: noise alone
   exceeds it with 1 % probability over the whole spectrum); harmonics above
   ``K`` are dropped.
4. The peak lift must stay within ``peak_tolerance`` of the scan's: ``K`` is
   raised until it does (said), or the load fails naming the field.

Smoothing (``smoothing = "spline"``), a cubic smoothing spline, for any
angle steps (unequal, or not dividing 360; the Fourier method needs equal
steps dividing 360):

1. The noise rms ``s`` is estimated from each interior point's residual
   against the chord of its two neighbours, ``r_i = y_i - (a y_{i-1} +
   b y_{i+1})`` (``a``, ``b`` the linear-interpolation weights), scaled by
   ``1 / sqrt(1 + a^2 + b^2)`` (for white noise ``E r_i^2 = s^2 (1 + a^2 +
   b^2)``): ``s^2`` is their mean square (not a median: quantised scans make
   most residuals exactly 0), unless ``noise`` is given. A lift's curvature
   adds ``h^2 |L''| / 8`` to a residual, small against the noise at scan
   steps of a degree or so.
2. ``scipy.interpolate.make_smoothing_spline`` fits the scan (a full
   revolution wrapped by 30 deg on each side, so the fit is periodic; a
   partial scan is fitted as it is and extended with base-circle lift 0);
   its penalty ``lam`` is chosen by the discrepancy principle: the mean
   square residual at the scan's points equals ``s^2`` (bisection on
   ``log lam``). A scan covers the revolution when the gap across 360 deg is
   no wider than its widest step (or twice its median step).
3. The peak lift must stay within ``peak_tolerance``: ``lam`` is lowered
   until it does (said), or the load fails naming the field.
4. The spline is sampled at equal steps (the scan's median step, rounded to
   divide 360); ``harmonics`` defaults to the fewest whose series stays
   within ``s / 4`` of those samples.

The result says how far smoothing moved the lift (largest and rms change,
in the preset's length unit) and the peak change; lift below 0 after all
this (base-circle noise, the series' ringing there) is set to 0 and counted
(so the loader's ramp-junction warning, which those noise-sized kinks would
set off, is not given for a smoothed scan); ``harmonics`` defaults to
``K`` (the fit then reproduces the smoothed table). ``vtool cam show
--plot/--figure`` draws raw against smoothed lift, velocity and acceleration
(per cam degree). With quantisation ``q`` and noise rms ``s`` the raw second
differences scatter by about ``sqrt(6 (s^2 + q^2/12))`` length/deg^2; the
smoothed acceleration of a polydyne scan at 1 deg, 0.01 mm and 0.003 mm noise
stays within 0.002 mm/deg^2 of the true one (tests/test_cam_scan.py).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from vtool.errors import InputError

#: metres per unit of a scan's lift
LIFT_UNITS = {"m": 1.0, "mm": 1e-3, "in": 0.0254, "thou": 2.54e-5}
ANGLES = ("cam", "crank")
LIFT_OF = ("tappet", "valve")
SMOOTHING = ("none", "fourier", "spline")
WRAP_DEG = 30.0  # a full-revolution scan's points repeated on each side for a periodic spline fit
FALSE_ALARM = 0.01  # probability that noise alone sets the cut-off (whole spectrum)
PEAK_NOISE_FACTOR = 4.0  # default peak tolerance in noise rms
_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_POINT = re.compile(rf"^({_NUMBER}),({_NUMBER})$")


@dataclass(frozen=True)
class ScanSettings:
    """What a scan's numbers are (the ``[cam.scan]`` table)."""

    lift_unit: str | None = None  # None: the preset's length unit
    angle: str = "cam"
    lift_of: str = "tappet"
    rocker_ratio: float | None = None
    smoothing: str = "none"
    noise: float | None = None  # in lift_unit
    peak_tolerance: float | None = None  # in lift_unit


@dataclass(frozen=True)
class Smoothed:
    """A smoothed scan (see the module doc); lengths in the preset's unit, angles in cam degrees."""

    angles: np.ndarray
    raw: np.ndarray
    lift: np.ndarray
    harmonics: int
    noise_rms: float
    moved_max: float
    moved_rms: float
    peak_raw: float
    peak_smoothed: float
    peak_tolerance: float
    raised: bool  # the cut-off was raised (the spline's penalty lowered) to keep the peak
    method: str = "fourier"
    raw_angles: np.ndarray | None = None  # the scan's own angles when ``lift`` is resampled (spline)
    penalty: float | None = None  # the spline's lam
    periodic: bool = True  # the scan covers the revolution (else extended with base-circle lift)

    def text(self, unit: str) -> str:
        moved = (f"lift moved by at most {self.moved_max:.3g} {unit} (rms {self.moved_rms:.3g} {unit}); peak "
                 f"{self.peak_raw:.6g} -> {self.peak_smoothed:.6g} {unit} (tolerance {self.peak_tolerance:.3g} {unit})")
        if self.method == "spline":
            lowered = " (lowered to keep the peak)" if self.raised else ""
            return (f"smoothed by a cubic smoothing spline, penalty lam {self.penalty:.3g}{lowered} from the noise "
                    f"(rms {self.noise_rms:.3g} {unit}), sampled at {self.angles.size} equal steps, a series of "
                    f"{self.harmonics} harmonics: {moved}")
        raised = " (raised to keep the peak)" if self.raised else ""
        return (f"smoothed by a Fourier series of {self.harmonics} harmonics{raised}, cut off at the noise "
                f"(rms {self.noise_rms:.3g} {unit}): {moved}")


@dataclass(frozen=True)
class Scan:
    """A scan converted to cam degrees and tappet lift (preset length unit), and what was done to it."""

    angles: np.ndarray
    lifts: np.ndarray  # smoothed when asked
    raw: np.ndarray  # converted, not smoothed
    notes: tuple[str, ...]
    smoothed: Smoothed | None = None
    raw_angles: np.ndarray | None = None  # the angles of ``raw`` when they are not ``angles`` (a spline's)


# ----------------------------------------------------------------------------
# reading


def read_polyline(field: str, name: str, folder: Path | None) -> tuple[list[float], list[float]]:
    """(angles, lifts) from a polyline script: ``angle,lift`` points separated by spaces or new lines;
    words (``PLINE``, ``_pline``, ``C``) and ``;`` comments are skipped."""
    from vtool.presets.lift_table import read_table_text

    text = read_table_text(field, name, folder)
    angles: list[float] = []
    lifts: list[float] = []
    for number, line in enumerate(text.splitlines(), start=1):
        for token in line.split(";", 1)[0].split():
            if re.fullmatch(r"_?[A-Za-z]+", token):
                continue
            match = _POINT.match(token)
            if match is None:
                raise InputError(f"{field} line {number}", token, "a point angle,lift (no spaces) or a command word")
            angles.append(float(match.group(1)))
            lifts.append(float(match.group(2)))
    if not angles:
        raise InputError(field, name, "a polyline of angle,lift points")
    return angles, lifts


def settings_from(t: Any, length_unit: str) -> ScanSettings:
    """The ``[cam.scan]`` table (a :class:`vtool.presets.fields.Table`), checked."""
    lift_unit = t.string("lift_unit", default=length_unit, choices=tuple(LIFT_UNITS))
    angle = t.string("angle", default="cam", choices=ANGLES)
    lift_of = t.string("lift_of", default="tappet", choices=LIFT_OF)
    ratio = t.number("rocker_ratio", required=False, min_exclusive=0.0, max_value=100.0)
    if lift_of == "valve" and ratio is None:
        raise InputError(t.field("rocker_ratio"), None, "the rocker ratio (valve lift per tappet lift) "
                         "for a valve-lift scan")
    smoothing = t.string("smoothing", default="none", choices=SMOOTHING)
    noise = t.number("noise", unit=lift_unit, required=False, min_exclusive=0.0)
    peak = t.number("peak_tolerance", unit=lift_unit, required=False, min_exclusive=0.0)
    t.finish()
    return ScanSettings(lift_unit, angle, lift_of, ratio, smoothing, noise, peak)


# ----------------------------------------------------------------------------
# converting and smoothing


def convert(angles: list[float] | np.ndarray, lifts: list[float] | np.ndarray, settings: ScanSettings,
            length_unit: str, metres_per_length: float) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Cam degrees and tappet lift in the preset's unit, and a note per conversion made."""
    theta = np.asarray(angles, dtype=float)
    lift = np.asarray(lifts, dtype=float)
    notes = []
    unit = settings.lift_unit or length_unit
    if unit != length_unit:
        if unit not in LIFT_UNITS:
            raise InputError("cam.scan.lift_unit", unit, f"one of: {', '.join(LIFT_UNITS)}")
        factor = LIFT_UNITS[unit] / metres_per_length
        lift = lift * factor
        notes.append(f"lift in {unit} converted to {length_unit} (x {factor:.6g})")
    else:
        notes.append(f"lift taken in {length_unit} (the preset's unit)")
    if settings.angle == "crank":
        theta = theta / 2.0
        notes.append("crank degrees halved to cam degrees (four-stroke: 2 crank revolutions per cam revolution)")
    else:
        notes.append("angles taken as cam degrees")
    if settings.lift_of == "valve":
        ratio = float(settings.rocker_ratio)  # type: ignore[arg-type]  # given whenever lift_of is valve (the loader checks)
        lift = lift / ratio
        notes.append(f"valve lift divided by the rocker ratio {ratio:g} to tappet lift")
    else:
        notes.append("lift taken as tappet (cam follower) lift")
    return theta, lift, notes


def noise_rms(lift: np.ndarray) -> float:
    """The rms of white noise on a periodic sampled lift, from the upper half of its spectrum."""
    N = lift.size
    power = np.abs(np.fft.rfft(lift)[1:]) ** 2
    upper = power[power.size // 2:]
    return float(math.sqrt(np.median(upper) / (N * math.log(2.0)))) if upper.size else 0.0


def _uniform_revolution(theta: np.ndarray, lift: np.ndarray, field: str) -> tuple[np.ndarray, np.ndarray, str]:
    """Equal steps over one revolution; a partial scan is extended with base-circle lift."""
    steps = np.diff(theta)
    step = float(np.median(steps)) if steps.size else 0.0
    if steps.size < 2 or step <= 0.0 or np.abs(steps - step).max() > 1e-6 * max(step, 1.0):
        raise InputError(f"{field}.angles", f"{theta.size} points", "equal angle steps for smoothing = \"fourier\" "
                         "(smoothing = \"spline\" takes any steps)", "deg")
    count = 360.0 / step
    if abs(count - round(count)) > 1e-6 * count:
        raise InputError(f"{field}.angles", f"a step of {step:g}", "a step that divides 360 for smoothing = "
                         "\"fourier\" (smoothing = \"spline\" takes any steps)", "deg")
    count = int(round(count))
    span = theta.size
    if abs(theta[-1] - theta[0] - 360.0) < 1e-9:  # the closing point of a full revolution
        span -= 1
    if span >= count:
        return theta[:count], lift[:count], ""
    full = theta[0] + step * np.arange(count)
    extended = np.zeros(count)
    extended[:span] = lift[:span]
    return full, extended, (f"the scan covers {theta[span - 1] - theta[0]:g} of 360 cam deg: extended with "
                            "base-circle lift (0)")


def smooth(theta: np.ndarray, lift: np.ndarray, *, noise: float | None = None,
           peak_tolerance: float | None = None, field: str = "cam") -> Smoothed:
    """The truncated Fourier series of the module doc (``theta`` in cam deg, equal steps, one revolution)."""
    N = lift.size
    X = np.fft.rfft(lift)
    power = np.abs(X[1:]) ** 2
    s = noise_rms(lift) if noise is None else float(noise)
    tau = math.log(max(power.size, 1) / FALSE_ALARM)
    above = np.nonzero(power > tau * N * s * s)[0]
    K = int(above.max()) + 1 if above.size else 1
    tolerance = PEAK_NOISE_FACTOR * s if peak_tolerance is None else float(peak_tolerance)
    peak_raw = float(lift.max())
    raised = False
    while True:
        kept = X.copy()
        kept[K + 1:] = 0.0
        smoothed = np.fft.irfft(kept, N)
        if abs(float(smoothed.max()) - peak_raw) <= tolerance or K >= power.size:
            break
        K += 1
        raised = True
    if abs(float(smoothed.max()) - peak_raw) > tolerance:
        raise InputError(f"{field}.scan.peak_tolerance", tolerance,
                         f">= {abs(float(smoothed.max()) - peak_raw):.3g} (the peak moves that much with every harmonic)")
    moved = smoothed - lift
    return Smoothed(theta, lift, smoothed, K, s, float(np.abs(moved).max()), float(np.sqrt(np.mean(moved**2))),
                    peak_raw, float(smoothed.max()), tolerance, raised)


def chord_noise_rms(theta: np.ndarray, lift: np.ndarray) -> float:
    """The rms of white noise on a lift sampled at any steps, from the residuals against neighbours' chords
    (see the module doc)."""
    if theta.size < 3:
        return 0.0
    h1, h2 = theta[1:-1] - theta[:-2], theta[2:] - theta[1:-1]
    a, b = h2 / (h1 + h2), h1 / (h1 + h2)
    r = (lift[1:-1] - a * lift[:-2] - b * lift[2:]) / np.sqrt(1.0 + a * a + b * b)
    return float(np.sqrt(np.mean(r * r)))


def _fewest_harmonics(lift: np.ndarray, within: float) -> int:
    """The fewest harmonics whose series of the periodic samples ``lift`` stays within ``within`` of them."""
    X = np.fft.rfft(lift)
    top = max(1, X.size - 2)

    def error(K: int) -> float:
        kept = X.copy()
        kept[K + 1:] = 0.0
        return float(np.abs(np.fft.irfft(kept, lift.size) - lift).max())

    low, high = 1, top
    if error(high) > within:
        return high
    while low < high:  # the truncation error falls (nearly) monotonically with K: bisect
        mid = (low + high) // 2
        low, high = (low, mid) if error(mid) <= within else (mid + 1, high)
    return low


def smooth_spline(theta: np.ndarray, lift: np.ndarray, *, noise: float | None = None,
                  peak_tolerance: float | None = None, field: str = "cam") -> Smoothed:
    """The smoothing spline of the module doc (``theta`` in cam deg, increasing, any steps, at most a
    revolution)."""
    from scipy.interpolate import make_smoothing_spline

    order = np.argsort(theta, kind="stable")
    theta, lift = theta[order], lift[order]
    if theta.size and abs(theta[-1] - theta[0] - 360.0) < 1e-9:  # the closing point of a full revolution
        theta, lift = theta[:-1], lift[:-1]
    steps = np.diff(theta)
    if theta.size < 8 or steps.min() <= 0.0 or theta[-1] - theta[0] >= 360.0:
        raise InputError(f"{field}.angles", f"{theta.size} points", "at least 8 distinct angles within one "
                         "revolution for smoothing = \"spline\"", "deg")
    step = float(np.median(steps))
    count = int(min(3600, max(36, round(360.0 / step))))
    periodic = theta[0] + 360.0 - theta[-1] <= max(float(steps.max()), 2.0 * step)  # no wider gap at the wrap
    if periodic:
        before, after = theta > theta[-1] - WRAP_DEG, theta < theta[0] + WRAP_DEG
        X = np.concatenate([theta[before] - 360.0, theta, theta[after] + 360.0])
        Y = np.concatenate([lift[before], lift, lift[after]])
    else:
        X, Y = theta, lift
    s = chord_noise_rms(theta, lift) if noise is None else float(noise)
    tolerance = PEAK_NOISE_FACTOR * s if peak_tolerance is None else float(peak_tolerance)
    peak_raw = float(lift.max())
    grid = theta[0] + (360.0 / count) * np.arange(count)
    inside = np.ones(count, dtype=bool) if periodic else grid <= theta[-1]

    def fitted(log_lam: float) -> tuple[Any, np.ndarray]:
        spline = make_smoothing_spline(X, Y, lam=10.0**log_lam)
        return spline, spline(theta)

    low, high = -10.0, 12.0  # log10 lam: the discrepancy principle, mean square residual = s^2
    for _ in range(60):
        mid = 0.5 * (low + high)
        if float(np.mean((fitted(mid)[1] - lift) ** 2)) > s * s:
            high = mid
        else:
            low = mid
    log_lam, raised = low, False
    spline, at_points = fitted(log_lam)
    while abs(float(np.where(inside, spline(grid), 0.0).max()) - peak_raw) > tolerance and log_lam > -10.0:
        log_lam -= 0.25  # less smoothing until the peak is kept
        raised = True
        spline, at_points = fitted(log_lam)
    smoothed = np.where(inside, spline(grid), 0.0)
    if abs(float(smoothed.max()) - peak_raw) > tolerance:
        raise InputError(f"{field}.scan.peak_tolerance", tolerance,
                         f">= {abs(float(smoothed.max()) - peak_raw):.3g} (the peak moves that much at the least "
                         "smoothing)")
    moved = at_points - lift
    return Smoothed(grid, lift, smoothed, _fewest_harmonics(smoothed, max(s, 1e-12) / 4.0), s,
                    float(np.abs(moved).max()), float(np.sqrt(np.mean(moved**2))), peak_raw,
                    float(smoothed.max()), tolerance, raised, "spline", theta, 10.0**log_lam, periodic)


def _base_circle(lift: np.ndarray, unit: str, notes: list[str]) -> np.ndarray:
    """Lift below 0 (noise or ringing on the base circle) set to 0, and said: the cam's lift is >= 0."""
    below = lift < 0.0
    if below.any():
        notes.append(f"{int(below.sum())} points below 0 (base-circle noise, down to {lift.min():.3g} {unit}) "
                     "set to 0")
        return np.where(below, 0.0, lift)
    return lift


def prepare(angles: list[float], lifts: list[float], settings: ScanSettings, length_unit: str,
            metres_per_length: float, field: str = "cam") -> Scan:
    """Convert (and smooth, when asked) a scan read from a file; the notes say what was done."""
    theta, lift, notes = convert(angles, lifts, settings, length_unit, metres_per_length)
    if settings.smoothing == "none":
        return Scan(theta, _base_circle(lift, length_unit, notes), lift, tuple(notes))
    scale = LIFT_UNITS[settings.lift_unit or length_unit] / metres_per_length if (
        settings.lift_unit or length_unit) in LIFT_UNITS else 1.0
    if settings.lift_of == "valve":
        scale /= float(settings.rocker_ratio)  # type: ignore[arg-type]  # given whenever lift_of is valve (the loader checks)
    noise = None if settings.noise is None else settings.noise * scale
    peak = None if settings.peak_tolerance is None else settings.peak_tolerance * scale
    if settings.smoothing == "spline":
        result = smooth_spline(theta, lift, noise=noise, peak_tolerance=peak, field=field)
        if not result.periodic:
            scanned = float(theta.max() - theta.min())
            notes.append(f"the scan covers {scanned:g} of 360 cam deg: extended with base-circle lift (0)")
        notes.append(result.text(length_unit))
        return Scan(result.angles, _base_circle(result.lift, length_unit, notes), result.raw, tuple(notes), result,
                    result.raw_angles)
    theta, lift, extended = _uniform_revolution(theta, lift, field)
    if extended:
        notes.append(extended)
    result = smooth(theta, lift, noise=noise, peak_tolerance=peak, field=field)
    notes.append(result.text(length_unit))
    return Scan(theta, _base_circle(result.lift, length_unit, notes), lift, tuple(notes), result)


def per_degree_derivatives(theta_deg: np.ndarray, lift: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Velocity (length/deg) and acceleration (length/deg^2) of a sampled lift by central divided
    differences (any steps; periodic over 360 deg): what the raw scan says before any smoothing."""
    after = np.roll(theta_deg, -1)
    after[-1] += 360.0
    before = np.roll(theta_deg, 1)
    before[0] -= 360.0
    h_after, h_before = after - theta_deg, theta_deg - before
    slope_after = (np.roll(lift, -1) - lift) / h_after
    slope_before = (lift - np.roll(lift, 1)) / h_before
    velocity = (np.roll(lift, -1) - np.roll(lift, 1)) / (h_after + h_before)
    acceleration = 2.0 * (slope_after - slope_before) / (h_after + h_before)
    return velocity, acceleration


def series_derivatives(theta_deg: np.ndarray, lift: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Velocity and acceleration per cam degree of a band-limited periodic lift (exact for the series)."""
    N = lift.size
    step = float(np.median(np.diff(theta_deg)))
    X = np.fft.rfft(lift)
    omega = 2.0 * math.pi * np.arange(X.size) / (N * step)  # rad per degree of the k-th harmonic
    if N % 2 == 0:
        X[-1] = 0.0  # the Nyquist term has no well-defined derivative
    return np.fft.irfft(1j * omega * X, N), np.fft.irfft(-(omega**2) * X, N)


def from_table(t: Any, angles: list[float], lifts: list[float], units: Any, field: str) -> Scan:
    """The ``[cam.scan]`` table applied to a table read from a file (or inline): the converted and smoothed
    scan, its notes issued as :class:`vtool.errors.PresetNote` (one line, ``note: FIELD: ...``)."""
    import warnings

    from vtool.errors import PresetNote

    settings = settings_from(t, units.length)
    scan = prepare(angles, lifts, settings, units.length, units.metres_per_length, field)
    warnings.warn(PresetNote(f"{field}: {'; '.join(scan.notes)}"), stacklevel=3)
    return scan


def preset_scan(preset: str, units: Any) -> Scan | None:
    """The measured scan of a preset's ``[cam]`` (converted, smoothed as asked), or None without
    ``[cam.scan]``: ``vtool cam show`` draws it raw against smoothed."""
    from vtool.presets import find_preset, read_document
    from vtool.presets.fields import Table
    from vtool.presets.lift_table import read_lift_table

    path = find_preset(preset)
    cam = read_document(path).get("cam")
    if not isinstance(cam, dict) or not isinstance(cam.get("scan"), dict):
        return None
    if cam.get("lift_table"):
        angles, lifts = read_lift_table("cam.lift_table", str(cam["lift_table"]), path.parent, units.length)
    elif cam.get("polyline"):
        angles, lifts = read_polyline("cam.polyline", str(cam["polyline"]), path.parent)
    else:
        angles, lifts = list(cam.get("angles", [])), list(cam.get("lifts", []))
    settings = settings_from(Table(cam["scan"], "cam.scan"), units.length)
    return prepare(angles, lifts, settings, units.length, units.metres_per_length, "cam")
