"""Compiled Newmark integration of the valve train with clearances (numba), by concern:

* :mod:`.algebra`: the step operators' product, Cholesky, the stored inverses;
* :mod:`.forces`: contact forces and monitors, the Hertz law and its iteration;
* :mod:`.step`: the Newmark step of a layer, the sources, the predictor and
  corrector shared by every step;
* :mod:`.impacts`: the impact laws and the event rules (every back end's);
* :mod:`.output`: output rows and peaks;
* :mod:`.quiet`: the quiet loop (most steps);
* :mod:`.loop`: event location and the entry point :func:`run_chunk`.

The arrays travel in the records of :mod:`vtool.solvers.newmark.records`;
their slots are in :mod:`vtool.solvers.newmark.layout`. Every function is
``@jit`` (:mod:`vtool.jit`); with ``NUMBA_DISABLE_JIT=1`` the same source is
the plain-NumPy reference the tests compare the compiled kernel with.

Conventions
-----------
Full coordinates: the n elastic system coordinates q_1..q_n (0-based here).
Sources: prescribed motions as Fourier series (:mod:`vtool.solvers.model.sources`)
x_s(t) = c_s + Σ_k a_sk cos kωt + b_sk sin kωt. A configuration ``c`` is a
bit mask over the clearances (contact = 1). In configuration c the layer
vector z (size m) holds the full coordinates with every closed internal pair
tied, ordered **free first**: z[0:nf] are integrated, z[nf:m] are prescribed
(tied to a source through a closed external clearance). ``group`` maps a full
coordinate to its z index, ``kept`` a z index to one full coordinate.

Newmark step of length h in configuration c (general beta, gamma):

    z̃ = z + h ż + h²(1/2 - beta) z̈,   ż̃ = ż + h(1 - gamma) z̈
    S z̈_F = -C_FF ż̃_F - K_FF z̃_F - (M_FP z̈_P + C_FP ż_P + K_FP z_P)     (ΔP)
    S = M_FF + gamma h C_FF + beta h² K_FF          (thesis BMIV = S⁻¹)
    z_F = z̃_F + beta h² z̈_F,   ż_F = ż̃_F + gamma h z̈_F

with the prescribed values (z_P, ż_P, z̈_P) taken from the sources at t + h.
Standard and refined steps use stored products G = S⁻¹[C_FF | K_FF | ΔP's
other columns] (``CP_STD``, ``CP_FINE``): z̈_F = -G·(ż̃_F, z̃_F, …) is one
product; other step lengths (event location, the return to the step grid)
form ΔP and factor S by Cholesky.

Monitors (:func:`~.forces.monitors`): a closed clearance's contact force, an
open one's gap; a sign change is an event, located by re-stepping (Illinois).
Impact laws (per clearance, ``CL_LAW``: momentum, local, thesis) and the
release of pulling contacts after every transition: :mod:`.impacts`.

Law switches: the ``hertz`` and ``momentum`` arguments are None when no
clearance uses that law (:func:`~vtool.solvers.newmark.layout.laws`).
"""

from vtool.solvers.newmark.kernel.forces import hertz_force
from vtool.solvers.newmark.kernel.impacts import (
                apply_impacts,
                gap_velocity,
                release_pulling,
                shut_gap,
)
from vtool.solvers.newmark.kernel.loop import run_chunk
from vtool.solvers.newmark.kernel.step import sources

__all__ = ["apply_impacts", "gap_velocity", "hertz_force", "release_pulling", "run_chunk", "shut_gap", "sources"]
