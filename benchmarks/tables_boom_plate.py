"""Write the sonic-boom and plate tables of README.md, docs/sonic-boom.md and docs/plate.md.

Every number in those tables comes from here (house rule: numbers in docs
are produced by scripts). ``python benchmarks/tables_boom_plate.py`` rewrites
the generated blocks; ``tests/test_tables_boom_plate.py`` regenerates them and
fails when a committed block differs. No column holds a wall time, so every
column is deterministic; rows that depend on numpy/scipy (eigenproblems)
name their versions.
"""

from __future__ import annotations

import functools
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
import scipy

from vtool.markdown import replace_block, table

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
BOOM_DOC = ROOT / "docs" / "sonic-boom.md"
PLATE_DOC = ROOT / "docs" / "plate.md"
COMMAND = "python benchmarks/tables_boom_plate.py"
VERSIONS = f"numpy {np.__version__}, scipy {scipy.__version__}"

Table = tuple[list[str], list[list[str]]]


# ----------------------------------------------------------------------------
# sonic boom


def _brick_wall(rule: str) -> object:
    from vtool.assessments.sonic_boom.assess import assess
    from vtool.presets import PRESET_DIR, boom, read_document

    doc = read_document(PRESET_DIR / "boom-brick-wall.toml")
    for wall in doc["walls"]:
        wall["pseudo_height_rule"] = rule
    return assess(boom.load(doc))


def boom_wall_table() -> Table:
    """Brick walls, both pseudo-height rules: frequency, DAF and allowable p+ per criterion."""
    header = ["wall", "pseudo-height rule", "b [in]", "f source", "f [Hz]", "tau/T", "velocity DAF",
              "damage p+ [lb/ft^2]", "safe p+ [lb/ft^2]"]
    rows = []
    for rule in ("whole-unit", "exact"):
        a = _brick_wall(rule)
        by = {(r.structure, r.frequency_source, r.criterion): r for r in a.rows}
        for s in a.structures:
            for source, f in s.frequencies.items():
                if source == "measured" and rule == "exact":
                    continue  # the measured rows do not depend on the rule
                damage = by[(s.name, source, "damage-threshold")]
                safe = by[(s.name, source, "safe-limit")]
                label = rule + (" (thesis, default)" if rule == "whole-unit" else "")
                rows.append([s.name, label if source != "measured" else "-",
                             f"{s.details['pseudo_height']:.2f}" if source != "measured" else "-",
                             source, f"{f:.3f}", f"{damage.ratio:.4f}", f"{damage.daf:.4f}",
                             f"{damage.pressure_alt:.3g}", f"{safe.pressure_alt:.3g}"])
    return header, rows


def boom_family_table() -> Table:
    """Envelope of the thesis family against the equal-rise option, pointwise."""
    from vtool.assessments.sonic_boom.spectra import EQUAL_RISE_ENVELOPE, THESIS_ENVELOPE, envelope

    ratio = np.round(np.arange(0.25, 2.51, 0.25), 10)
    fine = np.linspace(0.01, 2.5, 250)
    header = ["tau/T", "thesis family (P r2=(s-1)r1)", "governing", "equal-rise (P r2=r1)",
              "governing", "difference %"]
    rows = []
    for quantity in ("velocity", "displacement"):
        a = envelope(THESIS_ENVELOPE, ratio, quantity)
        b = envelope(EQUAL_RISE_ENVELOPE, ratio, quantity)
        for i, r in enumerate(ratio):
            rows.append([f"{r:g} ({quantity})", f"{a.daf[i]:.4f}", a.governing[i], f"{b.daf[i]:.4f}",
                         b.governing[i], f"{(b.daf[i] / a.daf[i] - 1) * 100:+.2f}"])
        fa = envelope(THESIS_ENVELOPE, fine, quantity).daf
        fb = envelope(EQUAL_RISE_ENVELOPE, fine, quantity).daf
        d = (fb / fa - 1) * 100
        rows.append([f"0.01-2.5 step 0.01 ({quantity})", "", "", "", "",
                     f"{d.min():+.2f} ... {d.max():+.2f}"])
    return header, rows


def boom_floor_table() -> Table:
    from vtool.assessments.sonic_boom.assess import assess
    from vtool.presets import load_preset

    a = assess(load_preset("boom-tall-building"))
    rules = {c.name: c.rule() for c in a.criteria}
    header = ["criterion", "limit (quantity, unit, how applied)", "f [Hz]", "tau [s]", "displacement DAF",
              "p+ [lb/ft^2]"]
    rows = [[r.criterion, rules[r.criterion], f"{r.frequency:.3f}", f"{r.tau:g}", f"{r.daf:.4f}",
             f"{r.pressure_alt:.3g}"] for r in a.rows]
    return header, rows


def boom_t_window_table() -> Table:
    """T pulse with beta = 0: the forced window now ends at s + r2 (VELDAF)."""
    from vtool.assessments.sonic_boom.pulses import idealized
    from vtool.assessments.sonic_boom.response import peak_response

    header = ["pulse", "tau/T", "forced velocity DAF, window to s + r2", "forced, window to s",
              "overall"]
    rows = []
    for ratio in (0.25, 0.5, 1.0):
        t = idealized("T", s=2.0, r1=0.2, r2=0.5, alpha=0.5, beta=0.0)
        cut = idealized("T", s=2.0, r1=0.2, r2=0.0, alpha=0.5, beta=0.0)
        a = peak_response(t, ratio).velocity
        b = peak_response(cut, ratio).velocity
        rows.append([t.label, f"{ratio:g}", f"{a.forced[0]:.4f}", f"{b.forced[0]:.4f}",
                     f"{a.overall[0]:.4f}"])
    return header, rows


# ----------------------------------------------------------------------------
# plate


def _study(name: str, transient: bool = False) -> object:
    from vtool.assessments.plate.study import run_study
    from vtool.presets import load_preset

    return run_study(load_preset(name).study, transient=transient)


def plate_frequency_table(name: str = "plate-table2", cases: tuple[str, ...] | None = None) -> Table:
    result = _study(name)
    free = [f for f in result.free if cases is None or f.case in cases]
    modes = max((f.exact for f in free), key=len)
    header = ["case", "KS", *[f"({m.m},{m.n}) %" for m in modes], "wmax/w11", "versions"]
    rows = []
    for f in free:
        errs = [f"{e:.3f}" for e in f.errors_pct] + [""] * (len(modes) - len(f.errors_pct))
        rows.append([f.case, str(f.size), *errs, f"{f.omega_max_ratio:.1f}", VERSIONS])
    return header, rows


@functools.cache
def _exact(load: str, modes: int, on: int | None = None) -> object:
    """Exact references of plate-table2 (cached: two tables share them); ``on``: the grid of ``on`` modes."""
    from vtool.assessments.plate.transient import exact_histories
    from vtool.presets import load_preset

    spec = load_preset("plate-table2")
    tau = None if on is None else _exact(load, on).tau  # type: ignore[attr-defined]
    return exact_histories(spec.study.plate, load, spec.study.transient.periods, modes, tau=tau)


def plate_transient_table() -> Table:
    """Full model A1 at omega_max h = 1 and modal: peak errors against 200 and 800 exact modes."""
    from vtool.assessments.plate.model import build_model
    from vtool.assessments.plate.study import TransientSettings, run_transient_case
    from vtool.presets import load_preset

    spec = load_preset("plate-table2")
    plate = spec.study.plate
    settings = spec.study.transient
    run = TransientSettings(cases=("A1",), loads=("uniform", "point"), omega_max_h=(1.0,),
                            periods=settings.periods, exact_modes=200)
    exact = {load: _exact(load, 200) for load in run.loads}
    fine = {load: _exact(load, 800, 200) for load in run.loads}
    model = build_model(plate, spec.study.case("A1"))
    rows_out = run_transient_case(plate, model, run, exact, fine)
    header = ["load", "A1 run", "quantity", "peak error %, 200 modes (thesis)", "+ peak %", "- peak %",
              "peak error %, 800 modes", "versions"]
    rows = []
    for r in rows_out:
        wh = "modal" if np.isnan(r.omega_max_h) else f"RK4 wmax*h = {r.omega_max_h:g}"
        for q in ("displacement", "velocity", "acceleration"):
            if r.load == "point" and q == "acceleration":
                continue  # no converged exact value
            cells = [r.errors_pct[q], r.signed_pct[q + "+"], r.signed_pct[q + "-"], r.errors_4n_pct[q]]
            rows.append([r.load, wh, q, *("n/a" if np.isnan(v) else f"{v:.2f}" for v in cells),
                         VERSIONS])
    return header, rows


def plate_truncation_table() -> Table:
    from vtool.assessments.plate.report import truncation_pct
    from vtool.assessments.plate.transient import peak_at_end
    from vtool.presets import load_preset

    spec = load_preset("plate-table2")
    periods = spec.study.transient.periods
    header = ["load", "quantity", "exact peak, 200 modes", "at t/T", "800 modes", "200-mode change %",
              f"peak at the end of the {periods:g}-period window"]
    rows = []
    for load in ("uniform", "point"):
        coarse = _exact(load, 200)
        fine = _exact(load, 800, 200)
        change = truncation_pct(coarse, fine)
        for q in ("displacement", "velocity", "acceleration"):
            h, g = getattr(coarse, q), getattr(fine, q)
            k = int(np.argmax(np.abs(h)))
            sign = "+" if h[k] > 0 else "-"  # the peaks refined between the samples (exact series)
            fine_sign = "+" if g[int(np.argmax(np.abs(g)))] > 0 else "-"
            tag = ""
            if q == "acceleration" and not coarse.acceleration_defined:
                tag = " (does not converge)"
            elif q == "acceleration" and not coarse.acceleration_converged:
                tag = " (not converged)"
            rows.append([load, q, f"{coarse.extreme(q, sign):.4f}", f"{coarse.tau[k]:.3f}",
                         f"{fine.extreme(q, fine_sign):.4f}", f"{change[q]:+.2f}" + tag,
                         "yes" if peak_at_end(h, coarse.tau) else "no"])
    return header, rows


# ----------------------------------------------------------------------------

def session(*args: str, exit_code: int = 0) -> str:
    """``$ vtool ARGS`` and its output (and ``$ echo $?`` when it is to fail), as console lines."""
    from click.testing import CliRunner

    from vtool.app.cli.main import cli

    result = CliRunner().invoke(cli, list(args))
    if result.exit_code != exit_code:
        raise RuntimeError(f"vtool {' '.join(args)} exited {result.exit_code}, not {exit_code}: {result.output}")
    text = f"$ vtool {' '.join(args)}\n{result.output.rstrip()}\n"
    return text + (f"$ echo $?\n{exit_code}\n" if exit_code else "")


def console(*args: str) -> Callable[[], str]:
    """A block holding ``vtool ARGS`` and its output, as a console session."""
    return lambda: f"```console\n{session(*args)}```\n"


def plate_console() -> str:
    """docs/plate.md's command examples: their output as printed today (wall times vary; the test ignores
    them)."""
    parts = [session("plate", "modes", "plate-table2", "--case", "A1"),
             session("plate", "transient", "plate-table2", "--case", "A1", "--load", "uniform", "--scheme", "rk4",
                     "--wh", "1.0", "--no-plot"),
             session("plate", "transient", "plate-table2", "--case", "A9", "--load", "point", "--scheme", "modal",
                     "--no-plot"),
             session("plate", "transient", "plate-table2", "--wh", "3.0", exit_code=2)]
    return "```\n" + "\n".join(parts) + "```\n"


def render(fn: Callable[[], Table]) -> Callable[[], str]:
    def run() -> str:
        header, rows = fn()
        return table(header, rows)

    return run


#: (file, block name) -> function giving the block's text
BLOCKS: dict[tuple[Path, str], Callable[[], str]] = {}
_wall = render(boom_wall_table)
for key, fn in (
    ((README, "boom-brick-wall"), _wall),
    ((BOOM_DOC, "boom-brick-wall"), _wall),
    ((BOOM_DOC, "boom-envelope-families"), render(boom_family_table)),
    ((BOOM_DOC, "boom-floor"), render(boom_floor_table)),
    ((BOOM_DOC, "boom-t-window"), render(boom_t_window_table)),
    ((BOOM_DOC, "boom-daf-envelope-console"), console("boom", "daf", "--envelope")),
    ((BOOM_DOC, "boom-wall-console"), console("boom", "wall", "boom-brick-wall")),
    ((README, "plate-table2"), render(lambda: plate_frequency_table("plate-table2",
                                                                    ("A1", "A5", "A6", "A9", "A11")))),
    ((PLATE_DOC, "plate-table2"), render(plate_frequency_table)),
    ((PLATE_DOC, "plate-transient-a1"), render(plate_transient_table)),
    ((PLATE_DOC, "plate-truncation"), render(plate_truncation_table)),
    ((PLATE_DOC, "plate-console"), plate_console),
):
    BLOCKS[key] = fn


def main(argv: list[str]) -> int:
    """Rewrite every block (or only those whose name is in ``argv``)."""
    done: dict[Callable[[], str], str] = {}
    for (path, name), fn in BLOCKS.items():
        if argv and name not in argv:
            continue
        if fn not in done:
            done[fn] = fn()
        changed = replace_block(path, name, done[fn])
        print(f"{path.relative_to(ROOT)} {name}: {'rewritten' if changed else 'unchanged'}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
