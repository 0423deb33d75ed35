"""Ctrl+C stops the test suite even inside a garbage-collector callback (tests/conftest.py).

The issue's "the test suite ends with a hypothesis KeyboardInterrupt traceback when interrupted by its
deadline (it still passes)": SIGINT landed in hypothesis' gc callback, where Python prints an exception
and drops it, so the interrupt was lost, the run went on and passed, and its warnings summary showed
``Exception ignored in: <function gc_cumulative_time.<locals>.gc_callback>`` with a KeyboardInterrupt
traceback. Here a pytest run of one test sends itself SIGINT from inside a gc callback.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

INTERRUPTED_IN_A_CALLBACK = """\
import gc, os, signal, time


def test_interrupted_inside_a_gc_callback():
    fired = []

    def callback(phase, info):
        if phase == "start" and not fired:
            fired.append(phase)
            os.kill(os.getpid(), signal.SIGINT)
            deadline = time.monotonic() + 0.3
            while time.monotonic() < deadline:
                pass

    gc.callbacks.append(callback)
    try:
        gc.collect()
    finally:
        gc.callbacks.remove(callback)
    time.sleep(3.0)  # the interrupt, delivered again, arrives here
"""


def test_an_interrupt_inside_a_gc_callback_stops_the_run(tmp_path: Path) -> None:
    test_file = tmp_path / "test_interrupted.py"
    test_file.write_text(INTERRUPTED_IN_A_CALLBACK)
    # the suite's conftest as a plugin (the file lies outside tests/), one process, no cache folder
    done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "tests.conftest", "-p", "no:cacheprovider",
                           "-p", "no:xdist", str(test_file)], cwd=ROOT, capture_output=True, text=True, timeout=120)
    output = done.stdout + done.stderr
    # Python's own handler: the interrupt dropped, "1 passed" (exit 0) and an "Exception ignored" traceback
    assert done.returncode == 2, output  # pytest's "interrupted"
    assert "KeyboardInterrupt" in output and "Exception ignored" not in output and " passed" not in output


INTERRUPTED_IN_THE_CLI = """\
import os, signal, threading

from click.testing import CliRunner

from vtool.app.cli.main import cli


def test_the_cli_takes_the_interrupt():
    # raised in the command (its imports, the kernel's load or the run), which says "interrupted", exits 130
    threading.Timer(0.2, os.kill, (os.getpid(), signal.SIGINT)).start()
    result = CliRunner().invoke(cli, ["solve", "gnilka-1a", "--degrees", "36000"])
    assert result.exit_code == 130


def test_never_reached():
    pass
"""


def test_an_interrupt_the_code_under_test_takes_still_stops_the_run(tmp_path: Path) -> None:
    """vtool's CLI, run in the test process, turns Ctrl+C into exit 130; the run stops after that test
    (the second test is not run) and ends as interrupted."""
    test_file = tmp_path / "test_interrupted.py"
    test_file.write_text(INTERRUPTED_IN_THE_CLI)
    done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "tests.conftest", "-p", "no:cacheprovider",
                           "-p", "no:xdist", str(test_file)], cwd=ROOT, capture_output=True, text=True, timeout=120)
    output = done.stdout + done.stderr
    assert done.returncode == 2 and "Interrupted: interrupted (SIGINT)" in output, output
    assert "1 passed" in output and "2 passed" not in output
