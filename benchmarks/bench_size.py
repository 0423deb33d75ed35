"""The model sized to the question, measured: writes the generated blocks of docs/cams.md.

Run: ``python3 benchmarks/bench_size.py``. Each size study runs its presets at
the top speed once per refinement; wall times are this machine's, in one
process (ratios to the warm one-element run). The deterministic columns are
regenerated and compared by tests/test_size.py.

Blocks written:

* ``surge-convergence``: the fixed-free bar's lowest frequency with n
  consistent-mass elements against (π/2) sqrt(k/m), and the observed order;
* ``cam-ramped``: the ramped-cam preset's fit and derivative extremes;
* ``table-vs-harmonic``: the harmonic cam as a table, run by every back end;
* ``size-1a``: ``vtool size gnilka-1a --rpm-max 12000``;
* ``size-ramped``: ``vtool size ramped-cam --rpm-max 4000``.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

from vtool.errors import RunError
from vtool.markdown import replace_block, table

DOCS = Path(__file__).resolve().parent.parent / "docs" / "cams.md"
SIZE_CASES = {"size-1a": ("gnilka-1a", 12000.0), "size-ramped": ("ramped-cam", 4000.0)}


def surge_rows() -> tuple[list[str], list[list[str]]]:
    """Fixed-free bar (the valve spring alone, k = 254 lbf/in, wire mass), n elements."""
    import scipy.linalg

    from vtool.solvers.model.assembly import assemble_full
    from vtool.solvers.model.spec import BAR, MemberSpec

    k, m = 254.0, 0.283 / 386.0 * math.pi * 0.07**2 / 4 * 36.0
    exact = 0.5 * math.pi * math.sqrt(k / m)
    rows, errors, ns = [], [], [1, 2, 4, 8, 16, 32]
    for n in ns:
        member = MemberSpec("valve_spring", BAR, 36.0, (0, 1), stiffness=k, mass=m, elements=n,
                            nodes=tuple(range(2, n + 1)))
        spec = _one_member_spec(member, n)
        M, K = assemble_full(spec)
        omega = float(np.sqrt(scipy.linalg.eigh(K, M, eigvals_only=True)[0]))
        errors.append(omega / exact - 1.0)
        order = "" if len(errors) < 2 else f"{math.log(errors[-2] / errors[-1], 2):.3f}"
        rows.append([str(n), f"{omega:.6g}", f"{exact:.6g}", f"{100 * errors[-1]:.4f}", order])
    return ["elements", "omega_1 (rad/s)", "(pi/2) sqrt(k/m) (rad/s)", "error (%)", "observed order"], rows


def _one_member_spec(member, n_coordinates: int):  # type: ignore[no-untyped-def]
    from vtool.solvers.model.spec import (
        CamSpec,
        ClearanceSpec,
        CoordinateSpec,
        DampingSpec,
        InitialSpec,
        MechanismSpec,
        RunSpec,
    )

    coordinates = tuple(CoordinateSpec(i, f"c{i}", "translation") for i in range(1, n_coordinates + 1))
    return MechanismSpec("one member", "in-lbf-s", 386.0, coordinates, (member,),
                         CamSpec(n_coordinates + 1, 0.1), None,
                         (ClearanceSpec("cam", 1, n_coordinates + 1, "external"),),
                         InitialSpec(("cam",), 1.0, 1.0), DampingSpec(), RunSpec(1000.0, 10.0, 1e-5))


def cam_rows(name: str) -> tuple[list[str], list[list[str]]]:
    from vtool.presets import load_preset
    from vtool.solvers.model.cam import cam_report

    r = cam_report(load_preset(name))
    u = r["length_unit"]
    rows = [["harmonics (tolerance fit)", str(r["harmonics"]), ""],
            ["largest fit error", f"{r['fit_max_error']:.3g}", u],
            ["rms fit error", f"{r['fit_rms_error']:.3g}", u],
            ["lift range", f"{r['lift_min']:.4g} .. {r['lift_max']:.6g}", u],
            ["highest harmonic that matters (1 % of peak acceleration)", str(r["highest_harmonic"]), ""]]
    for quantity, e in r["extremes"].items():
        rows.append([f"{quantity} at {r['rpm']:g} rpm", f"{e['min']:.5g} .. {e['max']:.5g}", e["unit"]])
    rows.append(["ramp/flank junctions flagged", str(len(r["junctions"])), ""])
    return ["quantity", "value", "unit"], rows


def table_vs_harmonic_rows() -> tuple[list[str], list[list[str]]]:
    """gnilka-1a against its harmonic cam given as a 72-point table (4 harmonics), 400 deg, per back end."""
    from dataclasses import replace

    from vtool.presets import PRESET_DIR, load_preset, read_document
    from vtool.presets.valvetrain import load
    from vtool.solvers.run import simulate

    doc = read_document(PRESET_DIR / "gnilka-1a.toml")
    angles = np.arange(0.0, 360.0, 5.0)
    doc["cam"] = {"coordinate": 9, "profile": "table", "angles": angles.tolist(),
                  "lifts": (0.5 + 0.5 * np.sin(np.radians(angles))).tolist(), "harmonics": 4}
    table_spec = load(doc)
    rows = []
    for backend in ("exact", "newmark", "scipy"):
        thesis = load_preset("gnilka-1a")
        thesis = replace(thesis, run=replace(thesis.run, backend=backend, degrees=400.0))
        a, b = simulate(thesis), simulate(replace(table_spec, run=thesis.run))
        same = [(e.clearance, e.kind) for e in a.events] == [(e.clearance, e.kind) for e in b.events]
        worst = max(abs(x.cam_angle - y.cam_angle) for x, y in zip(a.events, b.events, strict=True))
        bound = f"< 1e{math.ceil(math.log10(worst))}" if worst > 0 else "0"  # robust to round-off changes
        rows.append([backend, str(len(a.events)), "yes" if same else "no", bound])
    return ["back end", "events", "same sequence", "largest event-angle difference (deg)"], rows


def size_study_for(name: str, rpm: float):  # type: ignore[no-untyped-def]
    from vtool.presets import load_preset
    from vtool.solvers.studies.size import size_study

    return size_study(load_preset(name), rpm)


def size_block(study) -> str:  # type: ignore[no-untyped-def]
    from vtool.solvers.studies.size import study_rows

    header, rows = study_rows(study)
    parts = [f"{name} {n}" + ("" if ok else " (not converged)") for name, (n, ok) in study.elements.items()]
    lines = [table(header, rows), f"Recommended elements: {', '.join(parts)}."]
    if study.harmonics is not None:
        lines.append(f"Recommended harmonics: {study.harmonics[0]}"
                     + ("." if study.harmonics[1] else " (not converged)."))
    lines.append(f"Highest cam harmonic that matters: {study.cam_harmonic} ({study.cam_frequency_hz:.4g} Hz).")
    return "\n".join(lines) + "\n"


def main(argv: list[str]) -> None:
    replace_block(DOCS, "surge-convergence", table(*surge_rows()))
    replace_block(DOCS, "cam-ramped", table(*cam_rows("ramped-cam")))
    if not argv or "table-vs-harmonic" in argv:
        replace_block(DOCS, "table-vs-harmonic", table(*table_vs_harmonic_rows()))
    for block, (name, rpm) in SIZE_CASES.items():
        if argv and block not in argv:
            continue
        try:
            study = size_study_for(name, rpm)
        except RunError as exc:  # a table cam before the back ends take Fourier-series cams
            print(f"{block}: not written ({exc})")
            continue
        replace_block(DOCS, block, size_block(study))
        print(f"{block}: written")


if __name__ == "__main__":
    main(sys.argv[1:])
