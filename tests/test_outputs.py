"""Outputs, signals and the sweep's pool (issue 37, "CLI and outputs", "Files and other users").

Every output path goes through one check before any work (a FIFO, a device, a
folder, a missing or read-only folder, a symbolic link: one line, exit 2);
files are opened without following a final link and keep their mode; SIGTERM
cleans up as Ctrl+C does; ``--scheduler`` has one parser; the sweep's pool
imports the installed ``vtool`` whatever the current folder holds.
"""

from __future__ import annotations

import json
import os
import signal
import stat
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest
from click.testing import CliRunner

from vtool.app.cli.main import cli
from vtool.errors import InputError
from vtool.files import open_atomic, write_atomic
from vtool.presets import PRESET_DIR

SWEEP = ["sweep", "gnilka-1a", "--set", "run.rpm=10000,11000", "--set", "run.degrees=20", "--workers", "1"]

#: every command that writes a file, with its output flag last (the path is appended)
WRITERS = {
    "solve": ["solve", "gnilka-1a", "--degrees", "10", "--csv"],
    "solve-boom": ["solve", "boom-brick-wall", "--csv"],
    "solve-plate": ["solve", "plate-irs", "--csv"],
    "sweep": [*SWEEP, "--csv"],
    "sweep-find": ["sweep", "gnilka-1a", "--find", "jump-speed", "--workers", "1", "--csv"],
    "compare": ["compare", "gnilka-1a", "--degrees", "10", "--csv"],
    "accuracy": ["accuracy", "gnilka-1a", "--csv"],
    "boom-daf": ["boom", "daf", "--csv"],
    "boom-wall": ["boom", "wall", "boom-brick-wall", "--csv"],
    "boom-floor": ["boom", "floor", "boom-tall-building", "--csv"],
    "plate-modes": ["plate", "modes", "plate-irs", "--csv"],
    "plate-transient": ["plate", "transient", "plate-irs", "--csv"],
    "plate-study": ["plate", "study", "plate-irs", "--csv"],
    "presets-copy": ["presets", "copy", "gnilka-1a"],
}


def run(*args: str):  # type: ignore[no-untyped-def]
    return CliRunner().invoke(cli, list(args))


def one_line(result) -> str:  # type: ignore[no-untyped-def]
    lines = [line for line in result.stderr.splitlines() if not line.startswith("warning: ")]
    assert len(lines) == 1 and lines[0].startswith("error: "), result.stderr[-2000:]
    return lines[0]


def bad_paths(folder: Path) -> dict[str, tuple[str, str]]:
    """name -> (path, words of the refusal)."""
    fifo = folder / "fifo.csv"
    os.mkfifo(fifo)
    victim = folder / "victim.txt"
    victim.write_text("someone else's file\n")
    link = folder / "link.csv"
    link.symlink_to(victim)
    return {"fifo": (str(fifo), "not a device, pipe or socket"),
            "device": ("/dev/zero", "not a device, pipe or socket"),
            "folder": (str(folder), "not a folder"),
            "missing": (str(folder / "nowhere" / "x.csv"), "a file in an existing folder"),
            "symlink": (str(link), "not a symbolic link")}


@pytest.mark.parametrize("command", sorted(WRITERS))
def test_every_output_is_checked_before_any_work(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                 command: str) -> None:
    """Each bad path is refused in one line, exit 2, before the preset is even loaded."""
    import vtool.presets as presets

    def no_work(*args, **kwargs):  # type: ignore[no-untyped-def]
        raise AssertionError("the command started its work before checking the output path")

    for name in ("load_preset", "load_document"):
        monkeypatch.setattr(presets, name, no_work)
    import vtool.presets.paths as paths
    import vtool.solvers.studies.accuracy as accuracy

    monkeypatch.setattr(accuracy, "accuracy_study", no_work)
    monkeypatch.setattr(paths, "plan_sweep", no_work)
    for kind, (path, words) in bad_paths(tmp_path).items():
        if command == "presets-copy" and kind == "folder":
            continue  # a folder is where `presets copy` puts the file
        result = run(*WRITERS[command], path)
        assert result.exit_code == 2, (kind, result.output)
        assert words in one_line(result), (kind, result.stderr)
    assert (tmp_path / "victim.txt").read_text() == "someone else's file\n"


def test_accuracy_into_a_missing_folder_is_refused_before_the_study(tmp_path: Path) -> None:
    started = time.perf_counter()
    result = run("accuracy", "gnilka-1a", "--csv", str(tmp_path / "missing" / "a.csv"))
    assert result.exit_code == 2 and "a file in an existing folder" in one_line(result)
    assert time.perf_counter() - started < 5.0  # the study itself takes minutes


def test_presets_copy_into_a_folder_checks_the_file_it_would_write(tmp_path: Path) -> None:
    (tmp_path / "gnilka-1a.toml").mkdir()
    result = run("presets", "copy", "gnilka-1a", str(tmp_path))
    assert result.exit_code == 2 and "not a folder" in one_line(result)


# ----- links and modes ---------------------------------------------------------------------------

def test_a_link_at_the_output_is_refused_and_its_target_untouched(tmp_path: Path) -> None:
    victim = tmp_path / "victim"
    victim.write_text("private\n")
    link = tmp_path / "out.csv"
    link.symlink_to(victim)
    with pytest.raises(InputError, match="not a symbolic link"):
        write_atomic(link, "planted\n")
    assert victim.read_text() == "private\n" and link.is_symlink()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.csv", "victim"]


def test_a_link_planted_while_writing_is_not_followed(tmp_path: Path) -> None:
    """The check passed (no file yet); another user plants a link before the rename: refused."""
    victim = tmp_path / "victim"
    victim.write_text("private\n")
    target = tmp_path / "out.csv"
    with pytest.raises(InputError, match="not a symbolic link"), open_atomic(target) as handle:
        handle.write("rows\n")
        target.symlink_to(victim)
    assert victim.read_text() == "private\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.csv", "victim"]


def test_a_rewritten_output_keeps_its_mode_and_a_new_one_is_0644_under_the_umask(tmp_path: Path) -> None:
    private = tmp_path / "private.csv"
    private.write_text("old\n")
    private.chmod(0o600)
    write_atomic(private, "new\n")
    assert stat.S_IMODE(private.stat().st_mode) == 0o600 and private.read_text() == "new\n"
    old = os.umask(0o027)
    try:
        write_atomic(tmp_path / "new.csv", "x\n")
    finally:
        os.umask(old)
    assert stat.S_IMODE((tmp_path / "new.csv").stat().st_mode) == 0o640  # 0644 & ~027


def test_the_sweep_file_is_appended_without_following_a_link(tmp_path: Path) -> None:
    from vtool.presets.paths import plan_sweep
    from vtool.solvers.studies.sweep import SerialRunner, SweepFile, run_points

    victim = tmp_path / "victim"
    victim.write_text("private\n")
    plan = plan_sweep("gnilka-1a", ["run.rpm=10000,11000", "run.degrees=20"])
    sink = SweepFile(tmp_path / "s.csv", plan.fields, plan.spec)
    (tmp_path / "s.csv").symlink_to(victim)  # planted after the check, before the first point
    with pytest.raises(InputError, match="symbolic link"):
        run_points(plan.points, SerialRunner(), sink=sink)
    assert victim.read_text() == "private\n"


# ----- SIGTERM -----------------------------------------------------------------------------------

def long_preset(folder: Path) -> Path:
    """Example 1A with a row every 100 degrees: a long run writes its CSV slowly enough to be caught."""
    preset = folder / "presets" / "long.toml"
    preset.parent.mkdir()
    text = (PRESET_DIR / "gnilka-1a.toml").read_text()
    preset.write_text(text.replace("output_interval = 1.0 #", "output_interval = 100.0 #"))
    return preset


class _Terminated(Exception):
    """What the test's SIGTERM handler raises."""


def test_a_signal_as_the_temporary_file_is_made_is_taken_where_the_file_is_removed(tmp_path: Path,
                                                                                  monkeypatch) -> None:  # type: ignore[no-untyped-def]  # noqa: ANN001
    """SIGTERM delivered just after mkstemp made the file, before open_atomic knows its name (as a signal
    can land): the block that removes the file on failure finds it by its prefix, so nothing is left."""
    made = tempfile.mkstemp

    def made_then_signalled(*args, **kwargs):  # type: ignore[no-untyped-def]  # noqa: ANN002, ANN003, ANN202
        result = made(*args, **kwargs)
        os.kill(os.getpid(), signal.SIGTERM)
        return result

    def handler(signum, frame):  # type: ignore[no-untyped-def]  # noqa: ANN001, ANN202
        raise _Terminated

    out = tmp_path / "out.csv"
    out.write_text("previous\n")
    monkeypatch.setattr(tempfile, "mkstemp", made_then_signalled)
    before = signal.signal(signal.SIGTERM, handler)
    try:
        with pytest.raises(_Terminated), open_atomic(out) as handle:
            handle.write("new\n")
    finally:
        signal.signal(signal.SIGTERM, before)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.csv"]
    assert out.read_text() == "previous\n"


def test_sigterm_while_writing_leaves_no_temporary_and_the_old_file(tmp_path: Path) -> None:
    out = tmp_path / "out.csv"
    out.write_text("previous\n")
    proc = subprocess.Popen([sys.executable, "-m", "vtool", "solve", str(long_preset(tmp_path)), "--degrees",
                             "3600000", "--max-steps", "1e9", "--csv", str(out)],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    deadline = time.perf_counter() + 60.0
    while not list(tmp_path.glob(".out.csv.*.tmp")) and proc.poll() is None and time.perf_counter() < deadline:
        time.sleep(0.01)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 128 + signal.SIGTERM, err
    assert err.strip().splitlines()[-1] == "terminated: nothing was written"
    assert "Traceback" not in err
    assert out.read_text() == "previous\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.csv", "presets"]


def test_sigterm_during_a_sweep_keeps_the_finished_points_and_says_where(tmp_path: Path) -> None:
    out = tmp_path / "s.csv"
    proc = subprocess.Popen([sys.executable, "-m", "vtool", "sweep", "gnilka-1a", "--set",
                             "run.rpm=9000:12000:10", "--set", "run.degrees=360", "--workers", "1",
                             "--csv", str(out)], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    deadline = time.perf_counter() + 60.0
    while (not out.exists() or out.read_text().count("\n") < 3) and time.perf_counter() < deadline:
        time.sleep(0.02)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 128 + signal.SIGTERM and "Traceback" not in err, err
    assert err.strip().splitlines()[-1].startswith(f"terminated: the finished points are in {out}")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.csv"]
    rows = out.read_text().splitlines()
    assert len(rows) >= 3 and all(len(r.split(",")) == len(rows[0].split(",")) for r in rows)


# ----- --scheduler and --workers -----------------------------------------------------------------

@pytest.mark.parametrize("text", ["tcp://", "://", "inproc://x", "tls://127.0.0.1:8786", "ucx://127.0.0.1:1",
                                  "tcp://127.0.0.1:8786;touch x", "tcp://host:0", "tcp://host:99999",
                                  "local:0", "local:1000", "local:", "local-threads:x", "local:\u0663", ""])
def test_scheduler_strings_are_one_line_before_dask_starts(text: str) -> None:
    started = time.perf_counter()
    result = run(*SWEEP[:-2], "--scheduler", text)
    assert result.exit_code == 2 and one_line(result).startswith("error: --scheduler: got ")
    assert time.perf_counter() - started < 10.0


def test_local_workers_are_bounded_by_the_cores() -> None:
    from vtool.solvers.studies.sweep import LOCAL_WORKERS_PER_CORE, parse_scheduler

    top = LOCAL_WORKERS_PER_CORE * (os.cpu_count() or 1)
    assert parse_scheduler(f"local:{top}") == ("local", top)
    with pytest.raises(InputError, match=f"from 1 to {top}"):
        parse_scheduler(f"local:{top + 1}")
    result = run(*SWEEP[:-2], "--workers", str(top + 1))
    assert result.exit_code == 2 and "--workers" in one_line(result)


# ----- the pool and the current folder ----------------------------------------------------------

def test_a_folder_named_vtool_in_the_current_folder_does_not_break_the_pool(tmp_path: Path) -> None:
    (tmp_path / "vtool").mkdir()
    vtool = Path(sys.executable).with_name("vtool")
    command = [str(vtool)] if vtool.exists() else [sys.executable, "-m", "vtool"]
    result = subprocess.run([*command, *SWEEP[:-2], "--workers", "2", "--json"], cwd=tmp_path,
                            capture_output=True, text=True, timeout=300)
    assert result.returncode == 0 and "Traceback" not in result.stderr, result.stderr[-3000:]
    assert [p["status"] for p in json.loads(result.stdout)["points"]] == ["ok", "ok"]


def test_helper_processes_start_without_the_current_folder_and_deaf_to_ctrl_c() -> None:
    from vtool.solvers.studies.sweep import _pool_start

    probe = ("import signal, sys; print(signal.SIGINT in signal.pthread_sigmask(signal.SIG_BLOCK, []), "
             "'' in sys.path)")
    with _pool_start():
        inside = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    outside = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    # outside the block the folder is on the path as this process' environment has it (a user's
    # PYTHONSAFEPATH=1, or benchmarks/bench_suite_ab.py's, keeps it off)
    folder_outside = str(not os.environ.get("PYTHONSAFEPATH"))
    assert inside.stdout.split() == ["True", "False"] and outside.stdout.split() == ["False", folder_outside]
    assert signal.SIGINT not in signal.pthread_sigmask(signal.SIG_BLOCK, [])


def test_ctrl_c_while_the_pool_starts_prints_one_message_and_no_traceback(tmp_path: Path) -> None:
    proc = subprocess.Popen([sys.executable, "-m", "vtool", "sweep", "gnilka-1a", "--set",
                             "run.rpm=9000:12000:10", "--set", "run.degrees=3600", "--workers", "2"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, start_new_session=True)
    assert proc.stderr is not None
    os.set_blocking(proc.stderr.fileno(), False)
    seen = b""
    deadline = time.perf_counter() + 60.0
    while b"points" not in seen and time.perf_counter() < deadline:  # the bar's label: the pool starts now
        seen += proc.stderr.read() or b""
        time.sleep(0.01)
    time.sleep(0.3)  # the forkserver is importing numpy
    os.killpg(proc.pid, signal.SIGINT)
    os.set_blocking(proc.stderr.fileno(), True)
    err = (seen + proc.stderr.read()).decode()
    proc.wait(timeout=60)
    assert "Traceback" not in err and "KeyboardInterrupt" not in err, err
    assert err.count("interrupted") == 1, err


# ----- sweep files -------------------------------------------------------------------------------

def test_resume_refuses_a_fifo_without_reading_it(tmp_path: Path) -> None:
    fifo = tmp_path / "s.csv"
    os.mkfifo(fifo)
    result = subprocess.run([sys.executable, "-m", "vtool", *SWEEP, "--csv", str(fifo), "--resume"],
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 2 and "not a device, pipe or socket" in result.stderr


def test_a_sweep_stopped_before_its_first_point_leaves_an_existing_csv_alone(tmp_path: Path) -> None:
    from vtool.presets.paths import plan_sweep
    from vtool.solvers.studies.sweep import SerialRunner, SweepFile, run_points

    out = tmp_path / "s.csv"
    out.write_text("an earlier sweep\n")
    plan = plan_sweep("gnilka-1a", ["run.rpm=10000,11000", "run.degrees=20"])
    sink = SweepFile(out, plan.fields, plan.spec)
    outcome = run_points(plan.points, SerialRunner(), sink=sink, cancel=lambda: True)
    assert not outcome.complete and not sink.written
    assert out.read_text() == "an earlier sweep\n"


def test_plot_of_a_metric_empty_at_every_point_draws_an_empty_chart() -> None:
    result = run(*SWEEP[:-2], "--plot", "--metric", "seating_velocity_max")  # no seating in 20 degrees
    assert result.exit_code == 0, result.output
    assert "no finite value to draw" in result.stdout


@pytest.mark.parametrize("args", [["cam", "show", "gnilka-1a", "--json", "--plot"],
                                  [*SWEEP, "--json", "--plot"], [*SWEEP, "--json", "--map"],
                                  ["boom", "daf", "--json", "--plot"],
                                  ["boom", "wall", "boom-brick-wall", "--json", "--plot"],
                                  ["plate", "study", "plate-irs", "--json", "--plot"]])
def test_json_is_alone_on_stdout_or_the_chart_is_refused(args: list[str]) -> None:
    result = run(*args)
    assert result.exit_code == 2 and "with --json" in one_line(result) and result.stdout == ""


def test_a_tiny_top_speed_is_one_line() -> None:
    result = run("size", "gnilka-1a", "--rpm-max", "5e-324")
    assert result.exit_code == 2 and one_line(result).startswith("error: --rpm-max: got 5e-324")


def test_a_run_too_long_for_any_step_limit_is_one_line() -> None:
    result = run("solve", "gnilka-1a", "--rpm", "0.001", "--degrees", "3.6e6")
    assert result.exit_code == 2 and "more than the largest --max-steps" in one_line(result)


# ----- the every-step CSV's size -----------------------------------------------------------------

def test_an_every_step_csv_is_estimated_from_the_steps_and_refused_above_the_file_limit(tmp_path: Path) -> None:
    from vtool.presets import load_preset
    from vtool.presets.valvetrain import with_run_overrides
    from vtool.solvers.run import _assemble, run_cost

    out = tmp_path / "steps.csv"
    result = run("solve", "gnilka-1a", "--rpm", "1000", "--degrees", "360", "--every-step", "--csv", str(out))
    assert result.exit_code == 0, result.output
    spec = with_run_overrides(load_preset("gnilka-1a"), rpm=1000.0, degrees=360.0)
    estimate = run_cost(_assemble(spec), csv=True, csv_every_step=True)
    assert 0.8 < estimate.file_bytes / out.stat().st_size < 1.4  # measured 1.06
    assert estimate.bytes < 0.1 * estimate.file_bytes  # the memory holds only the interval rows
    refused = run("solve", "gnilka-1a", "--rpm", "100", "--degrees", "3600", "--every-step", "--csv",
                  str(tmp_path / "big.csv"))
    line = one_line(refused)
    assert refused.exit_code == 2 and "MB of CSV (6e+06 rows)" in line and "limit of 2 GB of CSV" in line
    assert sorted(p.name for p in tmp_path.iterdir()) == ["steps.csv"]


# ----- the default runner's choice -------------------------------------------------------------

def test_the_pool_is_chosen_only_where_it_wins() -> None:
    from vtool.solvers.studies.sweep import CHUNK_SECONDS, choose_workers

    cheap = choose_workers(0.009, 98, cores=2, load=0.5, start_seconds=2.0)  # 0.9 s serially: no pool pays
    assert cheap.workers == 1 and "run in this process" in cheap.reason
    costly = choose_workers(0.5, 998, cores=2, load=0.5, start_seconds=2.0)  # 500 s serially
    assert costly.workers == 2 and "2 worker processes" in costly.reason
    assert costly.chunk * 0.5 >= CHUNK_SECONDS and costly.chunk <= 998 / 4
    loaded = choose_workers(0.5, 998, cores=2, load=3.0, start_seconds=2.0)  # another job holds the cores
    assert loaded.workers == 1 and "1.0 of 2 cores free" in loaded.reason
    small = choose_workers(0.05, 998, cores=8, load=1.0, start_seconds=2.0)
    assert small.workers == 8 and small.chunk == 5  # 0.25 s of work a chunk


def test_the_default_runner_says_what_it_chose_and_gives_the_serial_results() -> None:
    from vtool.presets.paths import plan_sweep
    from vtool.solvers.studies.sweep import AutoRunner, SerialRunner, results_csv, run_points

    plan = plan_sweep("gnilka-1a", ["run.rpm=10000:10400:100", "run.degrees=20"])
    said: list[str] = []
    runner = AutoRunner(2, announce=said.append)
    try:
        auto = run_points(plan.points, runner)
    finally:
        runner.close()
    serial = run_points(plan.points, SerialRunner())
    assert len(said) == 1 and said[0].startswith("sweep: 3 more points of ") and runner.choice is not None
    assert (results_csv(auto.results, plan.fields, plan.spec)  # (the machine's wall time left out)
            == results_csv(serial.results, plan.fields, plan.spec))
