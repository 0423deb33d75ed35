"""The damping of a Hertz contact that gives the restitution the preset asks for.

A Hertz contact with Hunt–Crossley damping pushes with

    F = k δⁿ (1 + a δ̇ / v⁻)        (never pulling)

where δ is the overlap, δ̇ its rate and v⁻ the approach velocity at closing.
For one mass m meeting a fixed contact at v⁻ the coefficient of restitution
depends on a and n alone: with δ = X x, t = T τ, X = (m v⁻² / k)^(1/(n+1))
and T = X / v⁻, the impact is

    x'' = -xⁿ (1 + a x'),   x(0) = 0,  x'(0) = 1,

and e = -x'(τ₁) where x returns to 0. Since v dv/dx = -xⁿ (1 + a v), the
integral of v / (1 + a v) dv over the impact is -∮ xⁿ dx = 0 whatever n:

    a (1 + e) = ln( (1 + a) / (1 - a e) )

(Gonthier et al. 2004), so e depends on a alone. Hunt and Crossley's
a = 3(1 - e)/2 (and Lankarani–Nikravesh's 3(1 - e²)/4) are its expansions
for e near 1: a = 1.5, their "e = 0", rebounds at 0.488. Here a is the root
of that relation in (0, 1/e) (Brent, to 1e-13), exact for a lone mass; the
tests check it against the impact integrated numerically (:func:`rebound`)
and through the Newmark and scipy back ends (rebound = e to 1e-3). e(a)
falls from 1 at a = 0 towards 1/a for large a (1 + a x' stays > 0, so
|x'| < 1/a): e = 0 needs infinite damping, so a Hertz contact takes
e >= :data:`MIN_RESTITUTION` and the loader refuses less in one line (a
rigid contact with restitution 0 is the perfectly plastic impact).

The kernel (:func:`vtool.solvers.newmark.kernel.hertz_force`) computes
a = 3(1 - e')/2 from its restitution slot, so the contact problem passes
e' = 1 - 2a/3 there for a Hertz contact (:func:`kernel_restitution`).
"""

from __future__ import annotations

import math
from functools import lru_cache

MIN_RESTITUTION = 0.01  # a = 100 (n = 1.5): e ≈ 1/a below about 0.1


def rebound(a: float, n: float) -> float:
    """e of the dimensionless impact x'' = -xⁿ (1 + a x') from x = 0, x' = 1 (module doc)."""
    import numpy as np
    from scipy.integrate import solve_ivp

    def rhs(_t: float, y: np.ndarray) -> tuple[float, float]:
        return y[1], -max(y[0], 0.0) ** n * (1.0 + a * y[1])

    def back_at_zero(_t: float, y: np.ndarray) -> float:
        return float(y[0])

    back_at_zero.terminal, back_at_zero.direction = True, -1  # type: ignore[attr-defined]  # solve_ivp's event attributes
    solution = solve_ivp(rhs, (0.0, 1e4), (0.0, 1.0), method="DOP853", rtol=1e-11, atol=1e-13,
                         events=back_at_zero)
    return float(-solution.y_events[0][0][1])


@lru_cache(maxsize=256)
def damping_factor(restitution: float) -> float:
    """The Hunt–Crossley factor a that rebounds a lone mass at ``restitution``, any n (module doc)."""
    from scipy.optimize import brentq

    e = float(restitution)
    if e >= 1.0:
        return 0.0

    def excess(a: float) -> float:  # < 0 below the root, > 0 above it
        return math.log1p(a) - math.log1p(-a * e) - a * (1.0 + e)

    near_one = 1.5 * (1.0 - e * e) / (1.0 + e**3)  # the root's expansion near e = 1; half of it is below
    high = (1.0 / e) * (1.0 - 1e-15)
    if excess(high) <= 0.0:  # the root is within rounding of 1/e (1 - a e = (1 + a) exp(-a (1 + e)): e < 0.03)
        return high
    return float(brentq(excess, 0.5 * near_one, high, xtol=1e-15, rtol=1e-13))


def kernel_restitution(restitution: float) -> float:
    """The value of the kernel's restitution slot that makes its a = 3(1 - e')/2 the right one."""
    return 1.0 - damping_factor(restitution) / 1.5


def check_restitution(restitution: float) -> bool:
    """Whether a Hertz contact can have this restitution (see :data:`MIN_RESTITUTION`)."""
    return math.isfinite(restitution) and MIN_RESTITUTION <= restitution <= 1.0
