"""Regenerate docs/limits.md's measured figures: the nominal 1A runs and the cost guard's example line.

Run: ``python3 benchmarks/limits_docs.py --write`` (about half a minute; ``--check``
compares instead of writing and exits 1 on a difference). It writes the generated
blocks

* ``limits-nominal``: example 1A as shipped (the thesis' start, the local
  impact law) and from the quasi-static start the extremes table's variants
  use (tests/test_extremes.py ``variant()``): throw-off, first seating and its
  bounce, peak forces, largest valve coordinate, events;
* ``limits-sane``: what every run must satisfy (tests/test_extremes.py ``assert_sane``, its bounds);
* ``limits-default-damping``, ``limits-seat-warning``: the two preset warnings,
  with what deleting [damping] does to 1A's events and the warning 1A prints
  with its seat at -0.6 in;
* ``limits-cost-text``: the cost guard's rule and limits (solvers/cost.py's
  constants) and the step counts the page quotes;
* ``limits-cost-guard``: what ``vtool solve gnilka-1a --rpm 1.5`` prints;
* ``limits-step-limits``: the Newmark stability limit of every thesis example;
* ``limits-run-rules``: the rules while a run goes (divergence, resting
  contacts, chattering), their constants read from the contact problem
  (solvers/model/contact.py) and 1A's resting speed;
* ``limits-extremes``: the extremes table, each row measured by running the
  case tests/test_extremes.py runs (benchmarks/limits_extremes.py; about 20
  runs of 850 degrees, a few seconds once the kernel is compiled);
* ``limits-extremes-long``: the four cases the suite marks slow (100 rpm,
  20 revolutions of 1A and of example 2 at every step, restitution on every
  clearance, 3,600 degrees of cam bounces). ``--write`` writes them; ``--check``
  compares them only with ``--long``, and the regeneration test does not.

Everything here is deterministic (no wall times); tests/test_limits_docs.py
regenerates the blocks and compares them with the committed page.
"""

from __future__ import annotations

import copy
import sys
from pathlib import Path

from vtool.markdown import read_block, replace_block
from vtool.presets import PRESET_DIR, load_document, read_document
from vtool.solvers.run import simulate
from vtool.solvers.trace import CLOSED, OPENED, RELEASED, Trace

DOC = Path(__file__).resolve().parent.parent / "docs" / "limits.md"
VALVE = 7  # the valve coordinate of the thesis' mechanism


def _doc(velocities: str | None) -> dict:
    doc = copy.deepcopy(read_document(PRESET_DIR / "gnilka-1a.toml"))
    if velocities is not None:
        doc["initial"]["velocities"] = velocities
    return doc


def describe(trace: Trace) -> str:
    """One sentence of a run's figures (cam angles in deg, the preset's units)."""
    units = trace.spec.unit_system
    cam = [e for e in trace.events if e.clearance == "cam" and e.kind in (OPENED, RELEASED)]
    throw = next((e.cam_angle for e in cam if e.cam_angle % 360.0 < 180.0), None)
    seat = [e for e in trace.events if e.clearance == "seat" and e.kind == CLOSED]
    first_rev = [e for e in seat if e.cam_angle < 360.0]
    seating = (f"valve seats at {seat[0].cam_angle:.1f}° at {-seat[0].relative_velocity:.4g} {units.velocity}"
               if seat else "the valve never seats")
    if len(first_rev) > 1:
        bounces = ", ".join(f"{e.cam_angle:.1f}° at {-e.relative_velocity:.4g} {units.velocity}"
                            for e in first_rev[1:])
        seating += f" and re-seats {len(first_rev) - 1} time(s) in the first revolution ({bounces})"
    peaks = " / ".join(f"{p:,.0f}" for p in trace.peak_force)
    labels = "/".join(trace.force_label(k) for k in range(len(trace.spec.clearances)))
    throw_text = f"follower thrown off the cam at {throw:.1f}°" if throw is not None else "no throw-off"
    return (f"{throw_text}, {seating}, peak forces {labels} = {peaks} {units.force}, largest valve "
            f"coordinate q{VALVE} {trace.coordinate(VALVE).max():.4g} {units.length}, "
            f"{len(trace.events)} events over {trace.spec.run.degrees:g}°")


def nominal_block() -> str:
    shipped = simulate(load_document(_doc(None)))
    quasi = simulate(load_document(_doc("quasi-static")))
    return (f"The nominal 1A run as shipped (the thesis' start, the local impact law): {describe(shipped)}.\n"
            f"From the quasi-static start, which every variant below uses (so that the first revolution "
            f"shows the extreme's own physics, not the start shock): {describe(quasi)}.\n")


def cost_guard_block() -> str:
    from click.testing import CliRunner

    from vtool.app.cli.main import cli

    result = CliRunner().invoke(cli, ["solve", "gnilka-1a", "--rpm", "1.5"])
    if result.exit_code != 2:
        raise RuntimeError(f"vtool solve gnilka-1a --rpm 1.5 exited {result.exit_code}: {result.output}")
    return f"```\n$ vtool solve gnilka-1a --rpm 1.5\n{result.output.rstrip()}\n```\n"


THESIS = ("gnilka-1a", "gnilka-1b", "gnilka-1c", "gnilka-1d", "gnilka-2", "gnilka-3")


def _sci(value: float) -> str:
    """A number as the page writes it: 5 × 10⁷, 1 × 10⁻⁵ (a power of ten alone as 10⁻⁵)."""
    import math

    exponent = math.floor(math.log10(abs(value)))
    mantissa = value / 10.0**exponent
    power = "10" + str(exponent).translate(str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹"))
    return power if abs(mantissa - 1.0) < 1e-12 else f"{mantissa:g} × {power}"


def _problem(name: str):  # type: ignore[no-untyped-def]
    """The contact problem of a shipped preset (its event rules' defaults, its scales)."""
    from vtool.presets import load_preset
    from vtool.solvers.model.contact import ContactProblem
    from vtool.solvers.model.mechanism import assemble

    return ContactProblem(assemble(load_preset(name)))


def sane_block() -> str:
    """What ``assert_sane`` (tests/test_extremes.py) checks, with its bounds."""
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
    from tests.test_extremes import PEAK_FRACTION, PENETRATION, PULL, SHUT, SHUT_RATE

    units = load_document(_doc(None)).unit_system
    return (f"* contacts push and never pull (contact force ≥ −{_sci(PULL)} × peak);\n"
            f"* an open clearance is not penetrated (gap ≥ −{_sci(PENETRATION)} {units.length});\n"
            "* a closed clearance is shut exactly: gap and gap rate zero to round-off\n"
            f"  ({_sci(SHUT)} {units.length}, {_sci(SHUT_RATE)} {units.velocity}), computed from the trace as "
            "q_ahead − q_behind with\n  q9 the cam and q10 the seat;\n"
            "* every impact approaches: its relative velocity is below the resting-contact\n"
            "  speed (a bounce is never recorded as a closing);\n"
            "* the events chain from the start configuration to the last row's;\n"
            "* the valve rises no higher than its highest static lift plus a throw at\n"
            "  twice the cam's top speed (a rebound with e ≤ 1), through the rocker,\n"
            "  against a spring–mass at the lowest natural frequency;\n"
            f"* the peak force per clearance (over every step) is at least {100 * PEAK_FRACTION:g} % of the\n"
            "  largest sampled force (samples are interpolated and may exceed the step\n"
            "  values a little near the stability limit).\n")


def default_damping_block() -> str:
    """The warning for a preset without [damping], with what deleting the section does to 1A."""
    import warnings

    from vtool.presets.valvetrain import load

    shipped = _doc(None)
    bare = copy.deepcopy(shipped)
    del bare["damping"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the warning this block describes
        default = load(bare).damping
        events = [len(simulate(load_document(d)).events) for d in (shipped, bare)]
    if default.layers:
        raise RuntimeError("the default damping has layers: reword docs/limits.md's default-damping bullet")
    return (f"* no `[damping]` section: the default, ratio {default.default_ratio:g} on every mode of every\n"
            f"  layer with factor {default.factor:g}, is printed (deleting [damping] from 1A changes the\n"
            f"  events in {shipped['run']['degrees']:g}° from {events[0]} to {events[1]});\n")


def seat_warning_block() -> str:
    """The warning for a seat below the valve's whole quasi-static travel, on 1A with the seat at -0.6 in."""
    from vtool.solvers.model.mechanism import assemble
    from vtool.solvers.model.preflight import SAMPLES, seat_reach_warning

    doc = _doc(None)
    doc["seat"]["position"] = -0.6
    warning = seat_reach_warning(assemble(load_document(doc)))
    if warning is None:
        raise RuntimeError("1A with the seat at -0.6 in gave no seat warning")
    return ("* a seat the valve never reaches quasi-statically: every coordinate follows\n"
            "  the static-start shape scaled by the cam (q = q₀ q_cam / q_cam(0)), and the\n"
            f"  cam moves over its lift law's whole range (sampled at {SAMPLES} angles a\n"
            "  revolution), so the valve travels over q_v0 (base + [min L, max L]) / q_cam(0);\n"
            "  a seat below all of it is reached only by dynamic overshoot\n"
            "  (`solvers/model/preflight.py`). 1A with `seat.position = -0.6`:\n"
            f"  `warning: {warning}`.\n")


def cost_text_block() -> str:
    """The cost guard's rule, its limits and the step counts the page quotes, from solvers/cost.py."""
    from vtool.solvers import cost

    def steps(rpm: float, degrees: float, dt: float) -> float:
        return cost.estimate(backend="newmark", rpm=rpm, degrees=degrees, time_step=dt, output_interval=1.0,
                             every_step=False, omega_max=1.0, n_coordinates=1, n_sources=1,
                             n_clearances=1).steps

    run = _doc(None)["run"]
    slow = steps(100.0, run["degrees"], run["time_step"])
    crawl = steps(1.5, run["degrees"], run["time_step"])
    return (f"The work grows as degrees / (rpm · Δt): {run['degrees']:g}° at 100 rpm and "
            f"{run['time_step'] * 1e6:g} µs is {slow:,.0f} steps. Before a run, `solvers/run.py::simulate` "
            "estimates the steps (Newmark: t_end / Δt with t_end = degrees / (6 rpm); exact and scipy: "
            f"{cost.SAMPLES_PER_PERIOD:g} samples per period of the highest natural frequency) and the memory "
            f"(output rows × values per row × {cost.BYTES_PER_VALUE} bytes: the float copies and the CSV text, "
            "`solvers/cost.py` BYTES_PER_VALUE; plus the configuration tables) and refuses, exit 2, above "
            f"**{_sci(cost.MAX_STEPS)} steps** (scipy: {_sci(cost.MAX_SCIPY_STEPS)} samples) or "
            f"**{cost.MAX_BYTES / 1e9:g} GB**, in one line with the estimate and how to proceed; "
            f"`vtool solve gnilka-1a --rpm 1.5` ({crawl:.3g} steps):\n")


def run_rules_block() -> str:
    """The rules applied while a run goes, with the constants of solvers/model/contact.py (1A's scales)."""
    import math

    from vtool.solvers.newmark import layout

    problem = _problem("gnilka-1a")
    rules = problem.rules
    _, fp = problem.parameters()
    divergence = fp[layout.FP_XLIM] / problem.x_scale
    resting = problem.rest_velocity / problem.velocity_scale()
    window = problem.zeno_window * problem.omega_max / (2.0 * math.pi)
    units = problem.spec.unit_system
    return ("| what | rule | outcome | test |\n|---|---|---|---|\n"
            f"| divergence | any \\|q\\| > {divergence:g} × (cam amplitude + cam offset) | `RunError`: \"diverged at "
            "t = … s (cam angle … deg) in configuration …\" | `test_the_limit_is_sharp[1.001]`, "
            "`test_newmark.py::test_divergence_stops_with_time_and_configuration` |\n"
            f"| resting contacts | separations and bounces slower than {_sci(resting)} × amplitude × max(cam speed, "
            f"lowest natural frequency) ({problem.rest_velocity:.2g} {units.velocity} for 1A) stay closed until "
            "their force says otherwise | – | `test_newmark.py::test_restitution_bounces_end_in_resting_contact` |\n"
            f"| chattering | {rules.zeno_stick} events each within {window:g} of the shortest natural period of the "
            f"previous make the contacts involved stick; {rules.zeno_stop} stop the run | `RunError`: \"chattering "
            "contact: … at t = … s (cam angle … deg) in configuration …\" | "
            "`test_newmark.py::test_chattering_is_stopped_by_sticking_when_resting_is_disabled` |\n"
            "| cancel | polled between chunks of steps | `RunError`: \"cancelled at t = … s\" | used by the tests' "
            "wall-time watchdog |\n")


def step_limits_block() -> str:
    """The Newmark stability limit (linear acceleration, the thesis' step rule) of every thesis example."""
    from vtool.presets import load_preset
    from vtool.solvers.newmark.backend import stability_limit

    limits = {}
    for name in THESIS:
        problem = _problem(name)
        run = load_preset(name).run
        limits[name] = stability_limit(run.beta, run.gamma, problem.omega_max)
    values = sorted(set(f"{v * 1e6:.5g}" for v in limits.values()))
    if len(values) == 1:
        return (f"The Newmark step limit is {values[0]} µs for every thesis example "
                f"({', '.join(THESIS)}: the same stiffest configuration).\n")
    return "The Newmark step limit of the thesis examples: " + ", ".join(
        f"{name} {v * 1e6:.5g} µs" for name, v in limits.items()) + ".\n"


def _extremes():  # type: ignore[no-untyped-def]
    """benchmarks/limits_extremes.py, loaded by path (benchmarks/ is not a package)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("limits_extremes", Path(__file__).resolve().parent / "limits_extremes.py")
    module = importlib.util.module_from_spec(spec)  # type: ignore[arg-type]
    spec.loader.exec_module(module)  # type: ignore[union-attr]
    return module


def extremes_block() -> str:
    return _extremes().extremes_block()


def extremes_long_block() -> str:
    return _extremes().long_block()


BLOCKS = {"limits-sane": sane_block, "limits-nominal": nominal_block, "limits-default-damping": default_damping_block,
          "limits-seat-warning": seat_warning_block, "limits-cost-text": cost_text_block,
          "limits-cost-guard": cost_guard_block, "limits-step-limits": step_limits_block,
          "limits-run-rules": run_rules_block, "limits-extremes": extremes_block}
LONG_BLOCKS = {"limits-extremes-long": extremes_long_block}


def main(argv: list[str]) -> int:
    check = "--check" in argv
    status = 0
    blocks = BLOCKS | (LONG_BLOCKS if not check or "--long" in argv else {})
    for name, make in blocks.items():
        text = make()
        if check:
            same = read_block(DOC, name) == text
            print(f"docs/limits.md {name}: {'current' if same else 'differs'}")
            status |= not same
        else:
            print(f"docs/limits.md {name}: {'rewritten' if replace_block(DOC, name, text) else 'unchanged'}")
    return status


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
