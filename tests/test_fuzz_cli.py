"""CLI flag fuzzer and the CLI and file-output regressions of issue 14.

The fuzzer draws combinations of ``vtool solve`` flags (numbers at and past
every limit, NaN, inf, 5e-324, text, empty strings; output paths in missing,
read-only and device locations; presets of every kind) and asserts: no
traceback, exit code 0, 1 or 2, one ``error:``/``run failed:`` line on a
failure, no partial or temporary file, strict JSON on stdout, and a per-case
time bound. The cost guard keeps every drawn run short (``--max-steps`` is
drawn only from small or invalid values). ``VTOOL_FUZZ_CLI_CASES`` sets the
number of cases (CI: :data:`CI_CASES`).
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, given, seed, settings
from hypothesis import strategies as st

from vtool.app.cli.main import cli
from vtool.files import clean_stale_temporaries, finite_json, json_text, write_atomic
from vtool.presets import PRESET_DIR

CI_CASES = 120
CASES = int(os.environ.get("VTOOL_FUZZ_CLI_CASES", CI_CASES))
CASE_SECONDS = 60.0

NUMBERS = ["0", "-1", "nan", "inf", "-inf", "1e300", "5e-324", "1e-12", "1.5", "abc", "", "1e6", "1e-300"]
FLAG_VALUES = {
    "--rpm": NUMBERS + ["11000", "10500", "3000", "0.001"],
    "--dt": NUMBERS + ["1e-6", "2e-6", "1e-5", "0.1"],
    "--degrees": NUMBERS + ["30", "90", "1e-6", "3.6e6", "8.5e8"],
    "--max-steps": ["0", "-5", "nan", "abc", "1", "1000", "20000"],
    "--backend": ["newmark", "exact", "scipy", "euler", ""],
}
SWITCHES = ["--json", "--plot", "--every-step", "--events"]
PRESETS = ["gnilka-1a", "gnilka-2", "boom-brick-wall", "plate-irs", "no-such-preset", "."]


def run(*args: str):  # type: ignore[no-untyped-def]
    return CliRunner().invoke(cli, list(args))


def one_error_line(result) -> str:  # type: ignore[no-untyped-def]
    lines = [line for line in result.stderr.splitlines() if not line.startswith("warning: ")]
    assert len(lines) == 1, result.stderr[:2000]
    assert lines[0].startswith(("error: ", "run failed: ")) and len(lines[0]) <= 600, lines[0]
    return lines[0]


@st.composite
def flag_sets(draw: st.DrawFn) -> tuple[list[str], str]:
    args = ["solve", draw(st.sampled_from(PRESETS))]
    for flag in draw(st.lists(st.sampled_from(sorted(FLAG_VALUES)), max_size=4, unique=True)):
        args += [flag, draw(st.sampled_from(FLAG_VALUES[flag]))]
    if "--max-steps" not in args:
        args += ["--max-steps", "20000"]
    args += draw(st.lists(st.sampled_from(SWITCHES), max_size=2, unique=True))
    csv = draw(st.sampled_from(["none", "ok", "missing-dir", "empty", "folder", "device"]))
    return args, csv


@pytest.mark.slow
@seed(14)
@settings(max_examples=CASES, deadline=None, database=None, suppress_health_check=list(HealthCheck))
@given(case=flag_sets())
def test_flag_combinations_never_give_a_traceback_or_a_hang(tmp_path_factory: pytest.TempPathFactory,
                                                          case: tuple[list[str], str]) -> None:
    args, csv = case
    folder = tmp_path_factory.mktemp("cli")
    target = {"ok": str(folder / "out.csv"), "missing-dir": str(folder / "missing" / "out.csv"),
              "empty": "", "folder": str(folder), "device": "/dev/null"}.get(csv)
    if target is not None:
        args = [*args, "--csv", target]
    started = time.perf_counter()
    result = CliRunner().invoke(cli, args)
    seconds = time.perf_counter() - started
    assert result.exception is None or isinstance(result.exception, SystemExit), (
        f"{args}: {type(result.exception).__name__}: {result.exception}")
    assert result.exit_code in (0, 1, 2) and seconds < CASE_SECONDS, args
    names = sorted(p.name for p in folder.iterdir())
    assert names == (["out.csv"] if csv == "ok" and result.exit_code == 0 else []), (args, names)
    if result.exit_code == 0:
        if "--json" in args:
            json.loads(result.stdout)
    else:
        one_error_line(result)
    path = os.environ.get("VTOOL_FUZZ_LOG")
    if path:
        with open(path, "a", encoding="utf-8") as handle:
            handle.write(f"cli exit={result.exit_code} seconds={seconds:.3f}\n")


# ----- regressions: flags ------------------------------------------------------------------------

@pytest.mark.parametrize("args, text", [
    (["--rpm", "5e-324"], "error: --rpm: got 5e-324, expected >= 0.001 and <= 1e+06 rev/min"),
    (["--degrees", "5e-324"], "error: --degrees: got 5e-324, expected >= 1e-06"),
    (["--degrees", "1e300"], "error: --degrees: got 1e+300, expected"),
    (["--rpm", "nan"], "error: --rpm: got nan"),
    (["--rpm", "1.5"], "error: run too large: 9.44e+07 steps"),
    (["--rpm", "1e-12"], "error: --rpm: got 1e-12"),
    (["--dt", "1e-12"], "error: run too large: 1.29e+10 steps"),
    (["--degrees", "3.6e6"], "error: run too large: 5.45e+07 steps"),
    (["--rpm", "abc"], "error: Invalid value for '--rpm': 'abc' is not a valid float."),
    (["--backend", "euler"], "'euler' is not one of 'exact', 'newmark', 'scipy'"),
    (["--json", "--plot"], "error: --plot: got 'with --json', expected one of --json"),
])
def test_bad_flags_are_one_line_before_any_run(args: list[str], text: str) -> None:
    started = time.perf_counter()
    result = run("solve", "gnilka-1a", *args)
    assert result.exit_code == 2 and time.perf_counter() - started < 20
    assert one_error_line(result).startswith(text) or text in result.stderr


def test_the_cost_guard_says_how_to_proceed_and_max_steps_lets_the_run_go() -> None:
    refused = run("solve", "gnilka-1a", "--degrees", "90", "--max-steps", "1000")
    line = one_error_line(refused)
    assert "1.36e+03 steps" in line and line.endswith("--max-steps 1364")
    allowed = run("solve", "gnilka-1a", "--degrees", "90", "--max-steps", "1364")
    assert allowed.exit_code == 0, allowed.output


def test_an_override_speed_is_in_the_title() -> None:
    result = run("solve", "gnilka-1a", "--rpm", "10500", "--degrees", "30", "--json")
    assert json.loads(result.stdout)["title"] == (
        "Gnilka 1971 example 1A: three clearances, 10,500 RPM (override), valve seat")


def test_valvetrain_flags_on_a_boom_preset_are_one_house_line() -> None:
    result = run("solve", "boom-brick-wall", "--rpm", "9000")
    assert result.exit_code == 2
    assert one_error_line(result).startswith("error: --rpm: got 9000.0, expected no --rpm for boom-brick-wall")


def test_usage_errors_are_one_line_and_backend_lists_choices() -> None:
    result = run("solve")
    assert result.exit_code == 2 and one_error_line(result).startswith("error: Missing argument 'PRESET'.")
    assert "[exact|newmark|scipy]" in run("solve", "--help").stdout


def test_warnings_are_one_line_each(tmp_path: Path) -> None:
    import tomli_w

    from tests.test_fuzz_presets import base_doc

    doc = base_doc("gnilka-1a")
    del doc["damping"]
    doc["seat"]["position"] = -0.6
    doc["run"]["degrees"] = 30.0
    preset = tmp_path / "p.toml"
    preset.write_text(tomli_w.dumps(doc))
    result = run("solve", str(preset))
    assert result.exit_code == 0
    warnings = result.stderr.splitlines()
    assert [w[:30] for w in warnings] == ["warning: no [damping] section:", "warning: seat.position: the va"]


# ----- regressions: output files -----------------------------------------------------------------

@pytest.mark.parametrize("where, text", [
    ("missing/dir/x.csv", "a file in an existing folder"),
    ("", "--csv: got '', expected a file path"),
    (".", "a file path, not a folder"),
    ("/dev/null", "a regular file path (not a device"),
])
def test_bad_output_paths_are_one_line_and_write_nothing(tmp_path: Path, where: str, text: str) -> None:
    path = where if where in ("", "/dev/null") else str(tmp_path / where)
    result = run("solve", "gnilka-1a", "--degrees", "10", "--csv", path)
    assert result.exit_code == 2 and text in one_error_line(result)
    assert list(tmp_path.iterdir()) == []


LONG = "1" * 300  # a file name over the system's 255-byte limit: ENAMETOOLONG on any lookup (monkey seed 366)


@pytest.mark.parametrize("arguments, text", [
    (["solve", LONG], "preset: got '111"),
    (["solve", "gnilka-1a", "--degrees", "10", "--csv", LONG + ".csv"], "(File name too long)"),
    (["solve", "gnilka-1a", "--degrees", "10", "--csv", f"{LONG}/x.csv"], "a file in an existing folder"),
    (["presets", "copy", "gnilka-1a", LONG], "(File name too long)"),
    (["presets", "show", LONG], "preset: got '111"),
])
def test_names_too_long_for_the_system_are_one_line(tmp_path: Path, monkeypatch, arguments: list[str],  # type: ignore[no-untyped-def]
                                                    text: str) -> None:
    """Path.is_file and friends raise OSError (ENAMETOOLONG) instead of answering False: every probe
    of a typed path goes through vtool.files' safe ones."""
    monkeypatch.chdir(tmp_path)
    result = run(*arguments)
    assert result.exit_code == 2 and text in one_error_line(result)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_a_read_only_folder_is_one_line(tmp_path: Path) -> None:
    tmp_path.chmod(0o500)
    try:
        result = run("solve", "gnilka-1a", "--degrees", "10", "--csv", str(tmp_path / "x.csv"))
    finally:
        tmp_path.chmod(0o700)
    assert result.exit_code == 2 and "read-only" in one_error_line(result)


def test_a_symlink_is_refused_and_kept(tmp_path: Path) -> None:
    """Never written through (issue 37: a link planted in a shared folder redirected the write)."""
    from vtool.errors import InputError

    real = tmp_path / "real.csv"
    real.write_text("old\n")
    link = tmp_path / "link.csv"
    link.symlink_to(real)
    with pytest.raises(InputError, match="not a symbolic link"):
        write_atomic(link, "new\n")
    assert link.is_symlink() and real.read_text() == "old\n"


def test_a_full_disk_is_a_run_error_and_leaves_the_old_file(tmp_path: Path, monkeypatch) -> None:  # type: ignore[no-untyped-def]
    import errno

    from vtool.errors import RunError

    target = tmp_path / "out.csv"
    target.write_text("old\n")

    def full(*args, **kwargs):  # type: ignore[no-untyped-def]
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(os, "replace", full)
    with pytest.raises(RunError, match="the disk is full; nothing was written"):
        write_atomic(target, "new\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.csv"] and target.read_text() == "old\n"


def test_stale_temporaries_of_a_killed_write_are_cleaned_on_the_next_write(tmp_path: Path) -> None:
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                          text=True, check=True)
    target = tmp_path / "out.csv"
    stale = tmp_path / f".out.csv.{dead.stdout.strip()}.abc123.tmp"
    stale.write_text("half")
    live = tmp_path / f".out.csv.{os.getpid()}.def456.tmp"
    live.write_text("another writer")
    write_atomic(target, "whole\n")
    assert not stale.exists() and live.exists() and target.read_text() == "whole\n"
    live.unlink()
    assert clean_stale_temporaries(target) == []


def test_sigkill_during_a_run_leaves_the_existing_file_intact(tmp_path: Path) -> None:
    # a run of 3.6e6 degrees (5.4e7 steps, a row every 100 degrees): seconds even on a fast machine; it is
    # killed once its CSV is being written (the temporary file is there), and must still be running then
    preset = tmp_path / "presets" / "long.toml"
    preset.parent.mkdir()
    text = (PRESET_DIR / "gnilka-1a.toml").read_text()
    preset.write_text(text.replace("output_interval = 1.0 #", "output_interval = 100.0 #"))
    out = tmp_path / "out.csv"
    out.write_text("previous\n")
    proc = subprocess.Popen([sys.executable, "-m", "vtool", "solve", str(preset), "--degrees", "3600000",
                             "--max-steps", "1e9", "--csv", str(out)],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.perf_counter() + 60.0
    while not list(tmp_path.glob(".out.csv.*.tmp")) and proc.poll() is None and time.perf_counter() < deadline:
        time.sleep(0.01)
    proc.send_signal(signal.SIGKILL)
    assert proc.wait(timeout=30) == -signal.SIGKILL, "the run was not running when killed"
    assert out.read_text() == "previous\n" and list(tmp_path.glob(".out.csv.*.tmp"))
    write_atomic(out, "next\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.csv", "presets"]


def test_json_has_no_nan_or_infinity() -> None:
    cleaned, places = finite_json({"a": float("nan"), "b": [1.0, float("inf")], "c": "x"})
    assert cleaned == {"a": None, "b": [1.0, None], "c": "x"} and places == ["a: nan", "b[1]: inf"]
    assert json.loads(json_text({"peak": float("-inf")})) == {"peak": None, "non_finite": ["peak: -inf"]}


def test_numba_cache_falls_back_to_a_writable_folder_or_disables_caching(tmp_path: Path) -> None:
    """The first folder that can be made is used (a digest-named folder in it); when none can, caching is
    off with one warning line."""
    code = (
        "import os, vtool.numba_cache as nc\n"
        "made = nc._made\n"
        "nc._made = lambda folder: str(folder).startswith(os.environ['OK']) and made(folder)\n"
        "print(nc.configure([]))\n"
        "print(os.environ.get('NUMBA_CACHE_DIR'), nc.CACHE_ENABLED)\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    ok = subprocess.run([sys.executable, "-c", code], env={**env, "OK": str(tmp_path),
                        "XDG_CACHE_HOME": str(tmp_path)}, capture_output=True, text=True, check=True)
    folder, enabled = ok.stdout.splitlines()[1].split()
    assert folder.startswith(f"{tmp_path}/vtool/numba/kernels-") and enabled == "True"
    none = subprocess.run([sys.executable, "-c", code], env={**env, "OK": "/nowhere"}, capture_output=True,
                          text=True, check=True)
    assert none.stdout.splitlines()[1].endswith(" False")
    assert none.stderr.count("\n") == 1 and none.stderr.startswith("warning: numba's cache is off")
