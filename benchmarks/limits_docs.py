"""Regenerate docs/limits.md's measured figures: the nominal 1A runs and the cost guard's example line.

Run: ``python3 benchmarks/limits_docs.py --write`` (about half a minute; ``--check``
compares instead of writing and exits 1 on a difference). It writes the generated
blocks

* ``limits-nominal``: example 1A as shipped (the thesis' start, the local
  impact law) and from the quasi-static start the extremes table's variants
  use (tests/test_extremes.py ``variant()``): throw-off, first seating and its
  bounce, peak forces, largest valve coordinate, events;
* ``limits-cost-guard``: what ``vtool solve gnilka-1a --rpm 1.5`` prints;
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


BLOCKS = {"limits-nominal": nominal_block, "limits-cost-guard": cost_guard_block,
          "limits-extremes": extremes_block}
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
