"""Preset fuzzer: any preset of any kind gives a result, one clean line (exit 2 or 1), never a traceback.

A seeded hypothesis fuzzer mutates the shipped presets of every kind
(:data:`KIND_BASES`: valve trains, the table cam (its CSV beside the
preset, and written inline), sonic-boom walls and floors, condensed plates)
(delete or add keys, a contact made compliant (linear or hertz), numbers
scaled by 1e-8 to 1e8, wrong types, 0, negatives, NaN, +-inf, 1e+-300, ints
too large for a float, huge arrays and strings, duplicated entries, invalid
UTF-8, tables and arrays nested 5,000 deep) and runs each through ``vtool
solve`` in process. Every case must end with exit code 0, 1 or 2; a
non-zero exit prints exactly one ``error:``/``run failed:`` line on stderr
(``warning:`` lines aside), leaves no CSV and no temporary file, and every
case finishes within :data:`CASE_SECONDS`. Runs are short (valve trains:
``--max-steps`` 20,000, base runs of 90 degrees; boom and plate presets cut
to a few cases, :func:`small_doc`) so the CI cost stays low.

CI runs :data:`CI_CASES` valve-train cases and :data:`CI_KIND_CASES` of
every other kind; ``VTOOL_FUZZ_CASES=3000`` runs that many of every kind
(``VTOOL_FUZZ_KINDS=plate,boom_wall`` picks kinds; ``VTOOL_FUZZ_LOG=FILE``
collects one line per case). The regression tests below hold the
reproducers of every signature issue 14 listed.
"""

from __future__ import annotations

import copy
import math
import os
import time
import tomllib
from pathlib import Path
from typing import Any

import pytest
import tomli_w
from click.testing import CliRunner
from hypothesis import HealthCheck, given, seed, settings
from hypothesis import strategies as st

from vtool.app.cli.main import cli
from vtool.errors import InputError, PresetWarning, RunError
from vtool.presets import PRESET_DIR, load_document, parse_text, read_document

CI_CASES = 250
CI_KIND_CASES = 25  # of each kind other than the valve trains, in the suite
CASES = os.environ.get("VTOOL_FUZZ_CASES")
CASE_SECONDS = 60.0
FUZZ_MAX_STEPS = "20000"
VALVETRAIN = sorted(p.stem for p in PRESET_DIR.glob("gnilka-*.toml")) + ["ohv-pushrod-1a"]
TABLE_CAM = "ramped-cam"
#: kind -> the shipped presets it mutates ("table_cam": ramped-cam with its CSV beside it, or inline)
KIND_BASES: dict[str, list[str]] = {
    "valvetrain": VALVETRAIN,
    "table_cam": [TABLE_CAM, f"{TABLE_CAM}+inline"],
    "boom_wall": ["boom-brick-wall"],
    "boom_floor": ["boom-tall-building"],
    "plate": ["plate-table2", "plate-table3", "plate-irs"],
    "camshaft": ["four-cylinder-intake"],
}
ONLY_KINDS = [k for k in os.environ.get("VTOOL_FUZZ_KINDS", "").split(",") if k]


def cases_of(kind: str) -> int:
    """How many cases of ``kind`` this run makes (module doc)."""
    if ONLY_KINDS and kind not in ONLY_KINDS:
        return 0
    if CASES is not None:
        return int(CASES)
    return CI_CASES if kind == "valvetrain" else CI_KIND_CASES


BAD_VALUES: list[Any] = [
    0, 0.0, -1, -1.0, math.nan, math.inf, -math.inf, 1e300, -1e300, 1e-300, 5e-324, 10**400, -(10**400),
    "x", "", True, [], {}, [1.0] * 5000, "z" * 100_000, 0.001, 1e6, 8.5e8, 2, 0.75, [0.5, 0.5],
    {"closed": [], "default_ratio": 0.75},
]


def base_doc(name: str) -> dict[str, Any]:
    doc = tomllib.loads((PRESET_DIR / f"{name}.toml").read_text(encoding="utf-8"))
    doc.setdefault("run", {})["degrees"] = 90.0
    return doc


def small_doc(name: str) -> dict[str, Any]:
    """A shipped preset of any kind made cheap to run (a fuzz case takes well under a second unmutated)."""
    if name.endswith("+inline"):  # the table cam with its lift table written into the preset
        from vtool.presets.lift_table import read_lift_table

        doc = base_doc(name.removesuffix("+inline"))
        angles, lifts = read_lift_table("cam.lift_table", doc["cam"].pop("lift_table"), PRESET_DIR, "in")
        doc["cam"].update(angles=angles, lifts=lifts)
        return doc
    doc = tomllib.loads((PRESET_DIR / f"{name}.toml").read_text(encoding="utf-8"))
    if doc.get("kind") == "plate":
        doc["cases"] = doc["cases"][:2]
        doc["study"].update(convergence_meshes=[2, 4], frequencies=3)
        doc["transient"].update(cases=[c["name"] for c in doc["cases"]], loads=["uniform", "point"],
                                omega_max_h=[1.0], periods=0.5, exact_modes=20)
    elif doc.get("kind") == "camshaft":  # two valves of the quick bucket train (a whole revolution each)
        doc["camshaft"]["valves"] = [dict(v, train="direct-acting-bucket") for v in doc["camshaft"]["valves"][::4]]
    elif doc.get("kind", "").startswith("boom"):
        doc["design"]["points"] = 20
        doc["boom"]["positive_durations"] = doc["boom"]["positive_durations"][:1]
    else:
        doc["run"]["degrees"] = 90.0
    return doc


def containers(doc: Any, path: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    """Paths of every table and array in the document (the root included)."""
    found = [path]
    items = doc.items() if isinstance(doc, dict) else enumerate(doc) if isinstance(doc, list) else ()
    for key, value in items:
        if isinstance(value, dict | list):
            found += containers(value, (*path, key))
    return found


def at(doc: Any, path: tuple[Any, ...]) -> Any:
    for key in path:
        doc = doc[key]
    return doc


@st.composite
def mutated_text(draw: st.DrawFn, kind: str = "valvetrain") -> bytes:
    """A shipped preset of ``kind`` (:data:`KIND_BASES`) with one to three mutations, as file bytes."""
    doc = small_doc(draw(st.sampled_from(KIND_BASES[kind])))
    if doc.get("clearances") and draw(st.integers(0, 3)) == 0:  # a compliant contact (docs/contact.md)
        clearance = draw(st.sampled_from(doc["clearances"]))
        law = draw(st.sampled_from(["linear", "hertz"]))
        clearance["contact"] = law
        clearance["contact_stiffness"] = draw(st.sampled_from([1e3, 1e6, 1e8, 1e12, 1e13]))
        if law == "linear":
            clearance["contact_damping_ratio"] = draw(st.sampled_from([0.0, 0.5, 1.0, 5.0]))
        else:  # hertz takes 0.01 <= e <= 1 (solvers/model/hertz.py): 0 is refused in one line
            clearance["restitution"] = draw(st.sampled_from([0.0, 0.05, 0.5, 1.0]))
    for _ in range(draw(st.integers(1, 3))):
        target = at(doc, draw(st.sampled_from(containers(doc))))
        keys = list(target) if isinstance(target, dict) else list(range(len(target)))
        op = draw(st.sampled_from(["delete", "replace", "replace", "replace", "add", "duplicate",
                                   "scale", "scale", "scale"]))
        if op == "add" or not keys:
            if isinstance(target, dict):
                name = draw(st.sampled_from(["rmp", "lenght", "extra", "seat", "damping", "zeta"]))
                target[name] = copy.deepcopy(draw(st.sampled_from(BAD_VALUES)))
            else:
                target.append(copy.deepcopy(draw(st.sampled_from(BAD_VALUES))))
            continue
        key = draw(st.sampled_from(keys))
        if op == "delete":
            del target[key]
        elif op == "scale":  # a valid-looking number far from the thesis value: exercises the runs
            value = target[key]
            if isinstance(value, float) or (isinstance(value, int) and not isinstance(value, bool)
                                            and abs(value) < 2**53):
                target[key] = value * 10.0 ** draw(st.integers(-8, 8))
        elif op == "duplicate" and isinstance(target, list):
            target.append(copy.deepcopy(target[key]))
        else:
            target[key] = copy.deepcopy(draw(st.sampled_from(BAD_VALUES)))
    try:
        text = tomli_w.dumps(doc)
    except (TypeError, ValueError):  # e.g. a list mixing tables and numbers: no TOML for it
        text = tomli_w.dumps(small_doc(KIND_BASES[kind][0]))
    data = text.encode("utf-8")
    raw = draw(st.sampled_from(["none"] * 8 + ["utf8", "nest-array", "nest-table", "truncate"]))
    if raw == "utf8":
        cut = draw(st.integers(0, len(data)))
        data = data[:cut] + b"\xff\xfe" + data[cut:]
    elif raw == "nest-array":
        data += b"\nextra = " + b"[" * 5000 + b"]" * 5000 + b"\n"
    elif raw == "nest-table":
        data += b"\nextra = " + b"{a = " * 5000 + b"1" + b"}" * 5000 + b"\n"
    elif raw == "truncate":
        data = data[: draw(st.integers(0, len(data)))]
    return data


def check_case(tmp_path: Path, data: bytes, kind: str = "valvetrain") -> tuple[int, float]:
    """Run one preset through `vtool solve`; assert the house rules; return (exit code, seconds)."""
    folder = tmp_path / f"case{time.monotonic_ns()}"
    folder.mkdir()
    preset = folder / "case.toml"
    preset.write_bytes(data)
    inputs = ["case.toml"]
    if kind == "table_cam":  # the lift table beside the preset, as shipped
        (folder / f"{TABLE_CAM}.csv").write_bytes((PRESET_DIR / f"{TABLE_CAM}.csv").read_bytes())
        inputs.append(f"{TABLE_CAM}.csv")
    out = folder / "out.csv"
    limits = ["--max-steps", FUZZ_MAX_STEPS] if kind in ("valvetrain", "table_cam") else \
        ["--max-steps", "50000"] if kind == "camshaft" else []  # (a bucket's 720 deg: 40,000 steps)
    started = time.perf_counter()
    result = CliRunner().invoke(cli, ["solve", str(preset), "--csv", str(out), "--json", *limits])
    seconds = time.perf_counter() - started
    assert result.exception is None or isinstance(result.exception, SystemExit), (
        f"{type(result.exception).__name__}: {result.exception}")
    assert result.exit_code in (0, 1, 2)
    assert seconds < CASE_SECONDS
    leftovers = sorted(p.name for p in folder.iterdir()) == sorted(inputs + (
        ["out.csv"] if result.exit_code == 0 else []))
    assert leftovers, sorted(p.name for p in folder.iterdir())
    errors = [line for line in result.stderr.splitlines() if not line.startswith("warning: ")]
    if result.exit_code == 0:
        import json

        json.loads(result.stdout)  # strict JSON
        assert "nan" not in out.read_text().lower().split(",")
    else:
        assert len(errors) == 1 and len(errors[0]) <= 600, result.stderr[:2000]
        assert errors[0].startswith(("error: ", "run failed: "))
    import resource

    keep = os.environ.get("VTOOL_FUZZ_SAVE_SLOW")  # a folder: cases over 10 s are copied there
    if keep and seconds > 10.0:
        Path(keep, f"slow-{seconds:.0f}s-{time.monotonic_ns()}.toml").write_bytes(data)

    rss_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    log(f"preset kind={kind} exit={result.exit_code} seconds={seconds:.3f} maxrss_mb={rss_mb:.0f} "
        f"{errors[0][:60] if errors else ''}")
    return result.exit_code, seconds


def log(line: str) -> None:
    """Append a case's outcome to ``$VTOOL_FUZZ_LOG`` (for the figures of a long run)."""
    path = os.environ.get("VTOOL_FUZZ_LOG")
    if path:
        with open(path, "a", encoding="utf-8") as handle:
            handle.write(line + "\n")


def fuzz(kind: str) -> None:
    """``cases_of(kind)`` mutated presets of ``kind`` through :func:`check_case` (seeded)."""
    count = cases_of(kind)
    if not count:
        pytest.skip(f"VTOOL_FUZZ_KINDS leaves out {kind}")

    @seed(14)
    @settings(max_examples=count, deadline=None, database=None, derandomize=False,
              suppress_health_check=list(HealthCheck))
    @given(data=mutated_text(kind))
    def one(data: bytes) -> None:
        import tempfile

        with tempfile.TemporaryDirectory() as folder:
            check_case(Path(folder), data, kind)

    one()


@pytest.mark.slow
@pytest.mark.parametrize("kind", list(KIND_BASES))
def test_mutated_presets_never_give_a_traceback_or_a_hang(kind: str) -> None:
    fuzz(kind)


def test_every_kind_of_preset_is_fuzzed() -> None:
    """Every preset kind the loader knows has fuzz bases, each base loads and runs cleanly unmutated."""
    from vtool.presets.kinds import KINDS

    kinds = {load_document(small_doc(name), PRESET_DIR).kind for bases in KIND_BASES.values()
             for name in bases}
    assert kinds == set(KINDS)
    for kind, bases in KIND_BASES.items():
        for name in bases:
            import tempfile

            with tempfile.TemporaryDirectory() as folder:
                code, _ = check_case(Path(folder), tomli_w.dumps(small_doc(name)).encode(), kind)
            assert code == 0, (kind, name)


# ----- regression tests: the reproducers of issue 14 ---------------------------------------------

def text_of(doc: dict[str, Any]) -> str:
    return tomli_w.dumps(doc)


def load_bytes(tmp_path: Path, data: bytes) -> Any:
    path = tmp_path / "p.toml"
    path.write_bytes(data)
    return load_document(read_document(path))


@pytest.mark.parametrize("nested", [b"x = " + b"[" * 5000 + b"]" * 5000,
                                    b"x = " + b"{a = " * 5000 + b"1" + b"}" * 5000])
def test_toml_nested_5000_deep_is_one_line(tmp_path: Path, nested: bytes) -> None:
    with pytest.raises(InputError) as info:
        load_bytes(tmp_path, nested)
    assert "nested too deep" in str(info.value) and "\n" not in str(info.value)


def test_invalid_utf8_names_the_byte_and_line(tmp_path: Path) -> None:
    data = (PRESET_DIR / "gnilka-1a.toml").read_bytes().replace(b"Gnilka 1971 example", b"Gnilka \xff1971", 1)
    with pytest.raises(InputError, match=r"got 'byte 0xff on line \d+', expected UTF-8 text"):
        load_bytes(tmp_path, data)


def test_int_too_large_for_a_float_is_refused_not_overflowing() -> None:
    for value in (10**400, [1.0, 10**400]):
        doc = base_doc("gnilka-1a")
        if isinstance(value, list):
            doc["members"]["pushrod"]["position"] = value
        else:
            doc["members"]["pushrod"]["length"] = value
        with pytest.raises(InputError) as info:
            load_document(doc)
        assert "characters)" in str(info.value) or "finite" in str(info.value)


@pytest.mark.parametrize("where, value", [
    (("gravity",), 1e300), (("members", "pushrod", "modulus"), 1e300), (("members", "valve", "density"), 1e-300),
    (("run", "time_step"), 1e-300), (("run", "degrees"), 8.5e8), (("run", "rpm"), 5e-324),
    (("cam", "amplitude"), math.inf), (("seat", "position"), math.nan),
])
def test_values_outside_the_physical_ranges_are_refused_before_any_numerics(where: tuple[str, ...],
                                                                          value: float) -> None:
    doc = base_doc("gnilka-1a")
    at(doc, where[:-1])[where[-1]] = value
    with pytest.raises(InputError, match=rf"^{'.'.join(where)}: got"):
        load_document(doc)


def test_a_duplicated_damping_layer_is_refused() -> None:
    doc = base_doc("gnilka-1a")
    doc["damping"]["layers"].append({"closed": [], "default_ratio": 0.75})
    with pytest.raises(InputError, match=r"damping.layers\[2\].closed: got \[\], expected a set of closed"):
        load_document(doc)


def test_an_ill_conditioned_mass_matrix_is_a_run_error_not_a_linalg_error() -> None:
    from vtool.solvers.model.damping import undamped_modes

    with pytest.raises(RunError, match="mass matrix is not positive definite"):
        undamped_modes(__import__("numpy").diag([1.0, -1.0]), __import__("numpy").eye(2))


def test_stiffness_and_mass_that_overflow_the_reduced_problem_are_a_run_error_not_nan_modes() -> None:
    """The NumPy reduction M^-1/2 K M^-1/2 overflows where LAPACK's generalized solver refused
    infinities: one line, never NaN frequencies passed on to the run."""
    import numpy as np

    from vtool.solvers.model.damping import undamped_modes

    for M, K in [(np.eye(2), 1e308 * np.array([[1.0, -1.0], [-1.0, 1.0]])),
                 (np.diag([1e300, 1e-300]), 1e300 * np.eye(2))]:
        with pytest.raises(RunError, match="overflow the reduced problem"):
            undamped_modes(M, K)


@pytest.mark.parametrize("changes", [{"rpm": 0.001}, {"degrees": 3.6e6}])
def test_runs_that_would_hang_are_refused_with_the_estimate(changes: dict[str, float]) -> None:
    from vtool.solvers.cost import CostError
    from vtool.solvers.run import simulate

    doc = base_doc("gnilka-1a")
    doc["run"].update(changes)
    started = time.perf_counter()
    with pytest.raises(CostError) as info:
        simulate(load_document(doc))
    assert time.perf_counter() - started < 10.0
    message = info.value.one_line()
    assert message.startswith("run too large: ") and "--max-steps" in message


def test_an_unknown_key_names_itself_and_the_closest_known_key() -> None:
    doc = base_doc("gnilka-1a")
    doc["run"]["rmp"] = doc["run"].pop("rpm")
    with pytest.raises(InputError, match=r"^run.rmp: got 11000.0, expected no such field .* \(did you mean `rpm`\?\)"):
        load_document(doc)
    doc = base_doc("gnilka-1a")
    doc["members"]["pushrod"]["lenght"] = 9.0
    with pytest.raises(InputError, match=r"did you mean `length`"):
        load_document(doc)


def test_a_missing_damping_section_is_a_warning_with_the_default() -> None:
    doc = base_doc("gnilka-1a")
    del doc["damping"]
    with pytest.warns(PresetWarning, match=r"no \[damping\] section: modal damping ratio 0.1"):
        load_document(doc)


def test_a_seat_never_reached_is_a_warning() -> None:
    from vtool.presets import load_preset
    from vtool.solvers.model.mechanism import assemble
    from vtool.solvers.model.preflight import seat_reach_warning

    assert seat_reach_warning(assemble(load_preset("gnilka-1a"))) is None
    doc = base_doc("gnilka-1a")
    doc["seat"]["position"] = -0.6
    message = seat_reach_warning(assemble(load_document(doc)))
    assert message is not None and message.startswith("seat.position: the valve (q7) moves between 0.5709 and 2.064 in")


def test_an_echoed_bad_value_is_cut_to_a_readable_line() -> None:
    doc = base_doc("gnilka-1a")
    doc["run"]["quantities"] = "q" * 5_000_000
    with pytest.raises(InputError) as info:
        load_document(doc)
    assert len(str(info.value)) < 500 and "(5,000,002 characters)" in str(info.value)


def test_parse_text_and_load_document_refuse_non_documents() -> None:
    with pytest.raises(InputError, match="valid TOML"):
        parse_text("a = [1,\n")
    with pytest.raises(InputError, match="a TOML document"):
        load_document([1, 2])  # type: ignore[arg-type]


def test_a_mode_number_with_thousands_of_digits_and_a_huge_title_are_refused() -> None:
    doc = base_doc("gnilka-1a")
    doc["damping"]["layers"][1]["mode_ratios"] = {"9" * 5000: 0.5}
    with pytest.raises(InputError, match=r"expected a mode number 1, 2, ..."):
        load_document(doc)
    doc = base_doc("gnilka-1a")
    doc["title"] = "t" * 100_000
    with pytest.raises(InputError, match=r"^title: got 'ttt.*characters\), expected a string of at most 10,000"):
        load_document(doc)


def test_a_run_whose_output_would_take_gigabytes_is_refused() -> None:
    """Found by the fuzzer: output every 1e-4 degree over 90 degrees (900,001 rows of 47 values)
    peaked at 3.7 GB; the memory estimate now refuses it."""
    from vtool.solvers.cost import CostError
    from vtool.solvers.run import simulate

    doc = base_doc("gnilka-1a")
    doc["run"]["output_interval"] = 1e-4
    with pytest.raises(CostError, match=r"about 2,8\d\d MB .* more than the limit of 2 GB of output"):
        simulate(load_document(doc))
