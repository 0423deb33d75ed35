"""CLI flag fuzzers and the CLI and file-output regressions of issues 14 and 37.

:func:`test_every_subcommand_never_gives_a_traceback_a_hang_or_a_damaged_file` draws from every
subcommand's own flags, read from the click commands themselves (so a new flag is fuzzed the day it
is added): values at and past every limit, text where numbers go, choices and non-choices, output
paths that are fine, missing, empty, a folder, a device, a FIFO or a symbolic link, presets of every
kind and none. It fails on a traceback, an exit code other than 0, 1 and 2, more than one error line,
JSON that does not parse, a case longer than :data:`CASE_SECONDS`, a temporary left behind, or an
output file that is empty or a CSV whose rows differ in width. ``VTOOL_FUZZ_CLI_ALL=N`` sets its
number of cases (default :data:`ALL_CI_CASES` in the suite; the issue-37 run used 1,500). ``vtool
tui`` is left out (it takes the terminal); its one flag is checked by tests/test_tui_presetfile.py.

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

import click
import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, given, seed, settings
from hypothesis import strategies as st

from vtool.app.cli.main import cli
from vtool.app.cli.options import OutputPath
from vtool.files import clean_stale_temporaries, finite_json, json_text, write_atomic
from vtool.presets import PRESET_DIR

CI_CASES = 120
CASES = int(os.environ.get("VTOOL_FUZZ_CLI_CASES", CI_CASES))
CASE_SECONDS = 120.0  # (a loaded 2-core machine: the slowest valid draw, a plate transient, takes ~10 s)
ALL_CI_CASES = 40
ALL_CASES = int(os.environ.get("VTOOL_FUZZ_CLI_ALL", ALL_CI_CASES))

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


# ----- every subcommand's flags (issue 37) --------------------------------------------------------

#: values for options by name (bounded so that a valid draw stays short: no --degrees that runs for long)
BY_NAME: dict[str, list[str]] = {
    "--degrees": ["0", "-1", "nan", "inf", "abc", "", "1e300", "5e-324", "5", "10"],
    "--rpm": NUMBERS + ["11000", "3000"],
    "--dt": NUMBERS + ["1e-6", "2e-6"],
    "--max-steps": ["0", "nan", "abc", "1", "1000", "20000"],
    "--rpm-max": ["nan", "0", "-1", "5e-324", "abc", "", "11000", "12000", "1e7"],
    "--max-elements": ["0", "1", "2", "65", "abc", "-3"],
    "--tolerance": ["0", "1", "0.01", "nan", "abc", "-1"],
    "--impact": ["local", "momentum", "thesis", "local,momentum", "bogus", "", ","],
    "--start": ["thesis", "rest", "bogus", "", "thesis,rest"],
    "--orders": ["q7", "F7", "q1-q9", "nope", "", "q999"],
    "--campbell": ["q7", "F7", "nope", ""],
    "--set": ["run.rpm=9000,10000", "run.rpm=10000", "run.rpm=1:2:0", "nope", "run.rpm=", "run.rpm=1e9",
              "members.valve_spring.stiffness=200,300", "run.degrees=1e9", "clearances[9].restitution=1",
              "run.rpm=9000:9001:1e-9", "=3", "run.rpm=abc"],
    "--workers": ["1", "0", "-1", "abc", "1000", "2", ""],
    "--scheduler": ["tcp://", "://", "inproc://x", "tls://a:1", "ucx://a:1", "tcp://a:1;b", "local:0", "local:1000",
                    "", "local-threads:1", "local:abc"],
    "--metric": ["spring_margin", "peak_F1", "seating_velocity_max", "nope", ""],
    "--case": ["G9", "full", "nope", "", "H5"],
    "--count": ["1", "6", "0", "501", "abc"],
    "--wh": ["0.01", "1", "2.8", "2.9", "0", "nan", "abc"],
    "--periods": ["0.5", "0.4", "21", "nan", "abc"],
    "--modes": ["2", "20", "1", "1001", "abc"],
    "--s": ["2", "1", "0.5", "nan", "inf", "abc", "1e300"],
    "--r1": ["0", "0.5", "1", "-1", "nan"], "--r2": ["0", "0.3", "1", "-0.1", "nan"],
    "--alpha": ["0", "0.5", "1", "2", "nan", "-1"], "--beta": ["0", "0.5", "1", "2", "nan", "-1"],
    "--damping": ["0", "0.05", "-1", "2", "nan", "1e-300"],
    "--range": ["0:2.5:0.01", "0:1:0", "abc", "5:1:1", "0:1e9:1e-9", "0:2:0.5", ""],
    "--preset": ["gnilka-1a", "nope"],
}
PRESET_NAMES = ["gnilka-1a", "gnilka-2", "ramped-cam", "boom-brick-wall", "boom-tall-building", "plate-irs",
                "no-such-preset", ".", ""]
#: presets of the kind each command takes (drawn three times in four, so that most draws get past the kind)
KIND_PRESETS = {"boom wall": ["boom-brick-wall"], "boom floor": ["boom-tall-building"],
                "plate modes": ["plate-irs"], "plate study": ["plate-irs"], "plate transient": ["plate-irs"],
                "presets show": PRESET_NAMES[:6], "presets copy": PRESET_NAMES[:6], "presets expand": PRESET_NAMES[:6]}
VALVETRAIN_PRESETS = ["gnilka-1a", "gnilka-2", "ramped-cam"]
OUTPUTS = ["ok", "missing-dir", "empty", "folder", "device", "fifo", "symlink"]
#: flags every draw of a command gets first (bounds on cost; a drawn value of the same flag comes after)
BASE: dict[str, list[str]] = {
    "solve": ["--max-steps", "20000", "--degrees", "30"],
    "sweep": ["--set", "run.degrees=20", "--workers", "1"],
    "accuracy": ["--degrees", "5"],
    "compare": ["--degrees", "10"],
    "size": ["--max-elements", "1"],
    "plate transient": ["--periods", "0.5"],
}
SKIPPED = ("tui",)


def _subcommands() -> dict[str, click.Command]:
    found: dict[str, click.Command] = {}

    def walk(command: click.Command, path: list[str]) -> None:
        if isinstance(command, click.Group):
            for name in command.list_commands(None):  # type: ignore[arg-type]
                walk(command.get_command(None, name), path + [name])  # type: ignore[arg-type]
        elif " ".join(path) not in SKIPPED:
            found[" ".join(path)] = command

    walk(cli, [])
    return found


SUBCOMMANDS = _subcommands()


def _values(param: click.Parameter) -> list[str] | None:
    """Values to draw for an option, or None for a path (drawn from OUTPUTS)."""
    name = param.opts[0]
    if name in BY_NAME:
        return BY_NAME[name]
    if isinstance(param.type, click.Choice):
        return [*param.type.choices, "bogus", ""]
    if isinstance(param.type, click.Path | OutputPath):
        return None
    if isinstance(param.type, click.types.IntParamType | click.IntRange):
        return ["0", "1", "-1", "abc", "", "99999999999999999999"]
    return NUMBERS


def _path(kind: str, folder: Path, suffix: str) -> str:
    return {"ok": str(folder / f"out{suffix}"), "missing-dir": str(folder / "missing" / f"out{suffix}"),
            "empty": "", "folder": str(folder), "device": "/dev/null", "fifo": str(folder / "fifo"),
            "symlink": str(folder / "link")}[kind]


@st.composite
def any_command(draw: st.DrawFn) -> tuple[str, list[str], dict[str, str]]:
    """(command, its arguments with placeholders ``{path:NAME}`` for output paths, and the kinds drawn)."""
    name = draw(st.sampled_from(sorted(SUBCOMMANDS)))
    command = SUBCOMMANDS[name]
    args = name.split() + list(BASE.get(name, []))
    paths: dict[str, str] = {}
    for param in command.params:
        if isinstance(param, click.Argument):
            if param.name in ("preset", "name"):
                fitting = KIND_PRESETS.get(name, VALVETRAIN_PRESETS if name != "solve" else PRESET_NAMES[:6])
                args.append(draw(st.sampled_from(fitting)) if draw(st.integers(0, 3)) else
                            draw(st.sampled_from(PRESET_NAMES)))
            else:  # presets copy DEST
                paths["DEST"] = draw(st.sampled_from(OUTPUTS + ["ok-folder"]))
                args.append("{path:DEST}")
    options = [p for p in command.params if isinstance(p, click.Option) and p.opts[0] not in ("--help",)]
    for param in draw(st.lists(st.sampled_from(options), max_size=3, unique_by=lambda p: p.opts[0])) if options else []:
        flag = param.opts[0]
        if param.is_flag:
            args.append(draw(st.sampled_from(param.opts + list(param.secondary_opts))))
            continue
        values = _values(param)
        if values is None:
            paths[flag] = draw(st.sampled_from(OUTPUTS))
            args += [flag, "{path:" + flag + "}"]
        else:
            for _ in range(draw(st.integers(1, 2)) if param.multiple else 1):
                args += [flag, draw(st.sampled_from(values))]
    return name, args, paths


def _check_file(path: Path) -> None:
    """An output file is whole: not empty; a CSV's rows all of one width; a preset parses as TOML."""
    data = path.read_bytes()
    assert data, f"{path.name} is empty"
    if path.suffix == ".csv":
        import csv
        import io

        rows = list(csv.reader(io.StringIO(data.decode("utf-8"))))
        assert len({len(r) for r in rows}) == 1, f"{path.name}: rows of widths {sorted({len(r) for r in rows})}"
    elif path.suffix == ".toml":
        import tomllib

        tomllib.loads(data.decode("utf-8"))


@pytest.mark.slow
@seed(37)
@settings(max_examples=ALL_CASES, deadline=None, database=None, suppress_health_check=list(HealthCheck))
@given(case=any_command())
def test_every_subcommand_never_gives_a_traceback_a_hang_or_a_damaged_file(
        tmp_path_factory: pytest.TempPathFactory, case: tuple[str, list[str], dict[str, str]]) -> None:
    name, template, paths = case
    folder = tmp_path_factory.mktemp("cli")
    os.mkfifo(folder / "fifo")
    (folder / "victim").write_text("someone else's\n")
    (folder / "link").symlink_to(folder / "victim")
    (folder / "sub").mkdir()
    suffix = {"--figure": ".png"}
    resolved = {flag: (str(folder / "sub") if kind == "ok-folder" else
                       _path(kind, folder, ".toml" if flag == "DEST" else suffix.get(flag, ".csv")))
                for flag, kind in paths.items()}
    args = [resolved[a[6:-1]] if a.startswith("{path:") else a for a in template]
    started = time.perf_counter()
    result = CliRunner().invoke(cli, args)
    seconds = time.perf_counter() - started
    assert result.exception is None or isinstance(result.exception, SystemExit), (
        f"{args}: {type(result.exception).__name__}: {result.exception}")
    assert "Traceback" not in result.output, (args, result.output[-2000:])
    assert result.exit_code in (0, 1, 2) and seconds < CASE_SECONDS, (args, result.exit_code, seconds)
    assert (folder / "victim").read_text() == "someone else's\n", args
    assert (folder / "link").is_symlink() and (folder / "fifo").is_fifo(), args
    left = sorted(p.name for p in folder.rglob("*") if p.name.endswith(".tmp"))
    assert not left, (args, left)
    for path in list(folder.glob("out*")) + list((folder / "sub").iterdir()):
        _check_file(path)
    if result.exit_code == 0:
        if "--json" in args and name not in ("presets copy",):
            json.loads(result.stdout)
    else:
        one_error_line(result)
    log = os.environ.get("VTOOL_FUZZ_LOG")
    if log:
        with open(log, "a", encoding="utf-8") as handle:
            handle.write(f"{name} exit={result.exit_code} seconds={seconds:.3f}\n")


def test_the_subcommand_fuzzer_reaches_every_subcommand_and_flag() -> None:
    """Every subcommand but the TUI is drawn from, with all of its options (a new one is fuzzed at once)."""
    assert set(SUBCOMMANDS) >= {"solve", "sweep", "size", "compare", "accuracy", "cam show", "boom daf",
                                "boom wall", "boom floor", "plate modes", "plate study", "plate transient",
                                "presets copy", "presets show", "presets list", "presets expand", "modes"}
    for name, command in SUBCOMMANDS.items():
        for param in command.params:
            if isinstance(param, click.Option) and not param.is_flag:
                values = _values(param)
                assert values is None or len(values) >= 4, (name, param.opts)
