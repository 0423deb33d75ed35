"""Free-motion amplitude from the Fourier transform of the pulse (thesis appendix A).

For the undamped oscillator, Duhamel's integral evaluated at the end of the
pulse gives the free-motion amplitude as the magnitude of the pulse's
Fourier transform at the natural frequency (equation A.6). In the
non-dimensional form of :mod:`~vtool.assessments.sonic_boom.response`
(``theta = omega t``, pressure over ``p+``),

.. math::

    |w| = \\Big|\\int_0^{\\theta_e} f(\\sigma)\\, e^{-i\\sigma}\\, d\\sigma\\Big|,

which equals both the free-motion displacement DAF and the free-motion
velocity DAF. Each segment's integral is closed-form; this module shares no
code with the time-domain solution, so the two are independent checks of
each other.
"""

from __future__ import annotations

import math

import numpy as np

from vtool.assessments.sonic_boom.pulses import Pulse


def _phi1(z: np.ndarray) -> np.ndarray:
    """``int_0^1 e^{z t} dt = (e^z - 1)/z``."""
    z = np.asarray(z, dtype=complex)
    small = np.abs(z) < 1e-3
    zs = np.where(small, 1.0, z)
    series = 1.0 + z / 2.0 + z * z / 6.0 + z**3 / 24.0 + z**4 / 120.0 + z**5 / 720.0
    return np.where(small, series, np.expm1(zs) / zs)


def _phi2(z: np.ndarray) -> np.ndarray:
    """``int_0^1 (1 - t) e^{z t} dt = (e^z - 1 - z)/z^2``."""
    z = np.asarray(z, dtype=complex)
    small = np.abs(z) < 1e-2
    zs = np.where(small, 1.0, z)
    series = (1.0 / 2.0 + z / 6.0 + z * z / 24.0 + z**3 / 120.0 + z**4 / 720.0
              + z**5 / 5040.0 + z**6 / 40320.0)
    return np.where(small, series, (np.expm1(zs) - zs) / (zs * zs))


def transform(pulse: Pulse, omega_tau: np.ndarray | float) -> np.ndarray:
    """Non-dimensional Fourier transform ``int f(t_hat) e^{-i w t_hat} dt_hat * w``.

    ``omega_tau`` is ``w tau`` (``u = 2 pi tau / T`` at the natural
    frequency). The factor ``w`` turns the transform of the normalized
    pulse into the free-motion amplitude: with ``theta = u t_hat``,
    ``int f e^{-i theta} d theta``. Zero ``omega_tau`` gives 0.
    """
    u = np.atleast_1d(np.asarray(omega_tau, dtype=float))
    total = np.zeros(u.shape, dtype=complex)
    for seg in pulse.segments:
        L = u * seg.length
        phase = np.exp(-1j * u * seg.start)
        # linear part: int_0^L (a + b s) e^{-i s} ds, b per unit theta
        b = np.divide(seg.slope, u, out=np.zeros_like(u), where=u > 0)
        w = -1j * L
        part = seg.level * L * _phi1(w)
        # int_0^L s e^{-is} ds = L^2 int_0^1 t e^{w t} dt = L^2 e^{w} phi2(-w)
        part = part + b * L * L * np.exp(w) * _phi2(-w)
        if seg.sinusoidal:
            Om = np.divide(seg.freq, u, out=np.zeros_like(u), where=u > 0)
            F = complex(seg.cos_amp, -seg.sin_amp)  # c sin + d cos = Re(F e^{i Om s})
            up = L * _phi1(1j * (Om - 1.0) * L)  # int e^{i(Om-1)s}
            down = L * _phi1(-1j * (Om + 1.0) * L)  # int e^{-i(Om+1)s}
            part = part + 0.5 * (F * up + F.conjugate() * down)
        total = total + phase * part
    return total


def free_amplitude(pulse: Pulse, ratio: np.ndarray | float) -> np.ndarray:
    """Free-motion DAF (displacement = velocity, undamped) against ``tau/T``."""
    ratio = np.atleast_1d(np.asarray(ratio, dtype=float))
    return np.abs(transform(pulse, 2.0 * math.pi * ratio))


def spectrum(pulse: Pulse, omega_tau: np.ndarray | float) -> np.ndarray:
    """Magnitude of the normalized pulse spectrum ``|P(w)| / (p+ tau)``."""
    u = np.atleast_1d(np.asarray(omega_tau, dtype=float))
    amp = np.abs(transform(pulse, u))
    return np.divide(amp, u, out=np.full_like(u, np.nan), where=u > 0)
