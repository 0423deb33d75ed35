"""The model sized to the question: elements per member and cam harmonics a speed range needs.

For a preset and the top of its speed range (``rpm_max``) the study

1. finds the highest cam harmonic that matters (acceleration amplitude k²|c_k|
   at least 1 % of the largest, from the widest fit the table allows; the
   harmonic cam has one) and the modes of the starting layer it can reach
   (ω <= 2 k_max ω_max);
2. refines each member in turn, the others at one element: n = 1, 2, 4, ...
   elements, one run each at ``rpm_max``, until doubling n changes every
   measured result by less than ``tolerance`` (relative): the peak force at
   every clearance and the largest seating velocity. The recommended n is the
   last one before that converged doubling. The results are those of the
   evaluated window (:func:`vtool.solvers.studies.metrics.evaluation_window`:
   after the first revolution, or the last cycle of a run to steady state),
   as ``vtool solve`` and ``vtool sweep`` report them, not the start-up
   shock. Peak forces are taken over the
   output rows (every ``output_interval`` degrees), not over every step: with
   rigid contacts the one-step force spike of an impact grows without bound
   as the element at the contact shrinks (gnilka-1a at 12,000 rpm, left
   rocker in 2, 4, 8, 16 elements: 13.6e3, 27.2e3, 55.4e3, 112e3 lbf at the
   rocker), so it cannot converge; compliant contacts remove that spike;
3. for a table cam, does the same with the number of Fourier harmonics
   K = 4, 8, 16, ... (one element per member).

Costs are measured, not estimated: each row carries its run's steps and wall
time, and the ratio to the one-element run of the same process (the wall
times are noisy on shared machines; the steps are exact). A refinement whose
highest mode ω_max would break Newmark's stability limit at the preset's step
(Ω = ω_max Δt >= 1/sqrt(γ/2 - β) for β < 1/4) runs with the step cut to 0.9
of that limit, and its extra cost shows in the steps.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from vtool.solvers import backends
from vtool.solvers.model.assembly import split_members, unsplit_members
from vtool.solvers.model.cam import (
    HARMONIC,
    MATTERS,
    WIDE_FIT,
    harmonic_that_matters,
    max_harmonics,
)
from vtool.solvers.model.mechanism import assemble
from vtool.solvers.model.spec import EXTERNAL, MechanismSpec
from vtool.solvers.studies.metrics import evaluation_window, run_metrics
from vtool.units import cam_speed


@dataclass(frozen=True)
class SizeRun:
    """One measured run of the study."""

    knob: str  # member name, "harmonics" or "baseline"
    value: int  # elements or harmonics
    coordinates: int
    results: dict[str, float]
    change: float | None  # largest relative change against the previous value of the same knob
    steps: int
    wall_time: float
    time_step: float


@dataclass(frozen=True)
class SizeStudy:
    rpm_max: float
    tolerance: float
    cam_harmonic: int
    cam_frequency_hz: float
    reachable_modes: list[tuple[float, str]]  # (ω rad/s, kind) of the starting layer
    runs: list[SizeRun]
    elements: dict[str, tuple[int, bool]]  # member -> (recommended n, converged)
    harmonics: tuple[int, bool] | None  # (recommended K, converged); None for a harmonic cam
    result_units: dict[str, str]


def result_names(spec: MechanismSpec) -> dict[str, str]:
    """The measured results and their units: peak force per clearance, largest seating velocity."""
    units = spec.unit_system
    names = {f"peak {c.name} force": units.force for c in spec.clearances}
    if any(c.kind == EXTERNAL and c.behind != spec.cam.coordinate for c in spec.clearances):
        names["max seating velocity"] = units.velocity
    return names


def measure(spec: MechanismSpec) -> tuple[dict[str, float], int, float]:
    """Run the spec: (results, steps, wall time)."""
    from vtool.solvers.run import simulate

    trace = simulate(spec)
    metrics = run_metrics(trace)  # the evaluated window, as solve and sweep report it: not the start-up shock
    start, end = evaluation_window(trace)
    rows = (trace.cam_angle >= start) & (trace.cam_angle <= end)
    sampled = trace.contact_force[rows].max(axis=0) if rows.any() else np.zeros(len(spec.clearances))
    results = {}
    for c, peak in zip(spec.clearances, sampled, strict=True):
        results[f"peak {c.name} force"] = float(peak)
    if "max seating velocity" in result_names(spec):
        seating = metrics["seating_velocity_max"]
        results["max seating velocity"] = 0.0 if math.isnan(seating) else float(seating)
    return results, trace.statistics.steps, trace.statistics.wall_time


def relative_change(new: dict[str, float], old: dict[str, float]) -> float:
    """max_i |new_i - old_i| / max(|new_i|, |old_i|) (0 when both are 0)."""
    change = 0.0
    for key, value in new.items():
        scale = max(abs(value), abs(old[key]))
        if scale > 0.0:
            change = max(change, abs(value - old[key]) / scale)
    return change


def stable_time_step(spec: MechanismSpec) -> float:
    """The preset's step, cut to 0.9 of its back end's stability limit for the model's highest mode
    (:meth:`~vtool.solvers.backends.Backend.stable_step`; a back end that takes no fixed step keeps it)."""
    backend = backends.get(spec.run.backend)
    if not backend.fixed_step:
        return spec.run.time_step
    return min(spec.run.time_step, 0.9 * backend.stable_step(assemble(spec)))


def with_elements(spec: MechanismSpec, member: str, n: int) -> MechanismSpec:
    plain = unsplit_members(spec)
    members = tuple(replace(m, elements=n if m.name == member else 1, nodes=()) for m in plain.members)
    return split_members(replace(plain, members=members))


def cam_reach(spec: MechanismSpec, rpm_max: float) -> tuple[int, float, list[tuple[float, str]]]:
    """(highest harmonic that matters, its frequency in Hz, reachable starting-layer modes)."""
    from vtool.solvers.model.assembly import surge_labels

    k_max = harmonic_that_matters(spec.cam)
    omega = cam_speed(rpm_max)
    layer = assemble(spec).start_layer
    labels = surge_labels(spec, layer.T @ layer.modes.shapes)
    reach = [(float(w), label or "mechanism") for w, label in zip(layer.modes.omega, labels, strict=True)
             if 0.0 < w <= 2.0 * k_max * omega]
    return k_max, k_max * rpm_max / 60.0, reach


def size_study(spec: MechanismSpec, rpm_max: float, tolerance: float = 0.01, max_elements: int = 8,
               progress: Callable[[str], None] | None = None) -> SizeStudy:
    """Run the study described in the module doc."""
    base = replace(spec, run=replace(spec.run, rpm=rpm_max))
    base = with_elements(base, "", 1)
    runs: list[SizeRun] = []

    def run(knob: str, value: int, model: MechanismSpec, previous: dict[str, float] | None) -> SizeRun:
        if progress is not None:
            progress(f"{knob} {value}")
        dt = stable_time_step(model)
        results, steps, wall = measure(replace(model, run=replace(model.run, time_step=dt)))
        change = None if previous is None else relative_change(results, previous)
        row = SizeRun(knob, value, model.n_coordinates, results, change, steps, wall, dt)
        runs.append(row)
        return row

    measure(base)  # warm-up (kernel cache, first factorizations): the cost ratios compare warm runs
    baseline = run("baseline", 1, base, None)
    elements = {}
    for member in spec.members:
        previous, n, converged = baseline, 1, False
        while 2 * n <= max_elements:
            row = run(member.name, 2 * n, with_elements(base, member.name, 2 * n), previous.results)
            if row.change is not None and row.change < tolerance:
                converged = True
                break
            previous, n = row, 2 * n
        elements[member.name] = (n, converged)
    harmonics = None
    if spec.cam.profile != HARMONIC:
        top = min(max_harmonics(len(spec.cam.angles)), WIDE_FIT)

        def with_harmonics(K: int) -> MechanismSpec:
            return replace(base, cam=replace(base.cam, harmonics=K, tolerance=None))

        K, converged = min(4, top), False
        previous = run("harmonics", K, with_harmonics(K), None)
        while 2 * K <= top:
            row = run("harmonics", 2 * K, with_harmonics(2 * K), previous.results)
            if row.change is not None and row.change < tolerance:
                converged = True
                break
            previous, K = row, 2 * K
        harmonics = (K, converged)
    k_max, frequency, reach = cam_reach(base, rpm_max)
    return SizeStudy(rpm_max, tolerance, k_max, frequency, reach, runs, elements, harmonics,
                     result_names(spec))


def study_rows(study: SizeStudy, with_costs: bool = True) -> tuple[list[str], list[list[str]]]:
    """The convergence table (header, rows); ``with_costs=False`` drops the wall-time columns."""
    names = list(study.result_units)
    header = ["refined", "n", "coordinates", *[f"{n} ({u})" for n, u in study.result_units.items()],
              "change (%)", "steps"]
    if with_costs:
        header += ["wall (s)", "cost ratio"]
    base_wall = study.runs[0].wall_time or 1.0
    rows = []
    for r in study.runs:
        row = [r.knob if r.knob != "baseline" else "one element each", str(r.value), str(r.coordinates),
               *[f"{r.results[n]:.5g}" for n in names],
               "" if r.change is None else f"{100 * r.change:.2f}", str(r.steps)]
        if with_costs:
            row += [f"{r.wall_time:.3g}", f"{r.wall_time / base_wall:.2f}"]
        rows.append(row)
    return header, rows


def study_text(study: SizeStudy, title: str) -> str:
    from vtool.markdown import table

    header, rows = study_rows(study)
    lines = [title,
             f"at {study.rpm_max:g} rpm, tolerance {100 * study.tolerance:g} % on peak forces and seating velocity "
             "in the evaluated window (after the first revolution, or the last cycle of run.steady)",
             f"highest cam harmonic that matters (acceleration >= {MATTERS:.0%} of the largest): "
             f"{study.cam_harmonic} ({study.cam_frequency_hz:.4g} Hz)",
             "starting-layer modes it can reach (<= 2x that frequency): "
             + (", ".join(f"{w / (2 * math.pi):.4g} Hz ({kind})" for w, kind in study.reachable_modes) or "none"),
             "", table(header, rows), ""]
    parts = [f"{name} {n}" + ("" if ok else " (not converged)") for name, (n, ok) in study.elements.items()]
    lines.append("elements: " + ", ".join(parts))
    if study.harmonics is not None:
        K, ok = study.harmonics
        lines.append(f"harmonics: {K}" + ("" if ok else " (not converged)"))
    else:
        lines.append("harmonics: 1 (harmonic cam, exact)")
    return "\n".join(lines)
