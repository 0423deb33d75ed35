"""Sonic-boom benchmark: speed of exact DAF curves, and accuracy against sampling.

Run: ``python3 benchmarks/bench_boom.py``. Prints figures, asserts nothing.

1. Speed: a 500-point DAF curve (tau/T in (0, 2.5]) for each of the five
   idealized types, velocity only (the thesis' DAF) and both quantities;
   best of several runs, and as a ratio to one ``numpy.sin`` over the same
   points (a reference measured in the same process: these machines are noisy).
2. Accuracy of the alternative the issue names: a sampled (time-step)
   response spectrum. The thesis itself took the peak of the velocity sampled
   at 1/100 of the boom duration; we show the DAF error of that sampling
   against the exact curve, per type.
"""

from __future__ import annotations

import math
import time

import numpy as np

from vtool.assessments.sonic_boom.pulses import PULSE_TYPES, idealized
from vtool.assessments.sonic_boom.response import history, peak_response
from vtool.assessments.sonic_boom.spectra import THESIS_ENVELOPE, envelope

PARAMS = {"N": {}, "P": {"r1": 0.2}, "Q": {}, "R": {}, "T": {"r1": 0.2}}


def best_of(func, repeat: int = 7) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        func()
        times.append(time.perf_counter() - start)
    return min(times)


def main() -> None:
    ratio = np.linspace(2.5 / 500, 2.5, 500)
    pulses = {k: idealized(k, s=2.0, **PARAMS[k]) for k in PULSE_TYPES}
    reference = best_of(lambda: np.sin(ratio * 2 * math.pi), repeat=50)
    print("speed: 500-point DAF curve (tau/T 0.005..2.5), best of 7")
    total_v = total_b = 0.0
    for pulse in pulses.values():
        tv = best_of(lambda p=pulse: peak_response(p, ratio, quantities=("velocity",)))
        tb = best_of(lambda p=pulse: peak_response(p, ratio))
        total_v += tv
        total_b += tb
        print(f"  {pulse.label:<40} velocity {tv * 1e3:7.2f} ms   both {tb * 1e3:7.2f} ms")
    print(f"  all five types: velocity {total_v * 1e3:.1f} ms, displacement+velocity "
          f"{total_b * 1e3:.1f} ms  ({total_v / reference:.0f}x one numpy.sin over the points)")
    te = best_of(lambda: envelope(THESIS_ENVELOPE, ratio), repeat=3)
    print(f"  thesis envelope (91 pulses), velocity: {te * 1e3:.0f} ms")

    print("accuracy of a sampled spectrum (velocity peak sampled every 1/100 of the boom "
          "duration, forced + 1 free cycle, as the thesis did) against the exact DAF:")
    for kind, pulse in pulses.items():
        exact = peak_response(pulse, ratio, quantities=("velocity",)).velocity.overall
        errors = []
        for r, e in zip(ratio[::10], exact[::10], strict=True):
            dt = pulse.duration / 100.0
            t = np.arange(0.0, pulse.duration + 1.0 / r + dt, dt)  # one free period = 1/(tau/T) in t/tau
            _, v = history(pulse, float(r), t)
            errors.append((e - np.max(np.abs(v))) / e)
        errors = np.array(errors)
        print(f"  {kind}: max {100 * errors.max():.2f} %, mean {100 * errors.mean():.3f} % "
              f"(sampled peak always below: {bool(np.all(errors >= -1e-12))})")


if __name__ == "__main__":
    main()
