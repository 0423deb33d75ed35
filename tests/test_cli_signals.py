"""Ctrl+C where Python cannot unwind it at once: the CLI's signal handlers (app/cli/main.py).

Two places made Ctrl+C during a first compile end otherwise than with the one line and exit 130
(tests/test_first_run.py sends it at a fixed time, so it landed in them only now and then):

* source run by ``exec`` from a string (scipy's imports, dataclasses): an interrupt leaving it is
  remembered by CPython as unhandled, and ``python -m vtool`` then killed itself with SIGINT
  (returncode -2) after the clean message and exit 130 (1 run in 30 with Ctrl+C in the first 3 s);
* llvmlite's object-code callback, which LLVM calls from C through ctypes during numba's compile:
  ctypes printed and dropped the interrupt, so the run went on (exit 0) or numba failed with "no
  compiled object yet" (a traceback, exit 1).

Each case is built directly: a module run with ``python -m`` sends itself SIGINT inside such code and
busy-waits there, then sleeps outside it; it exits 130 when the interrupt arrives after the code.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

PROLOGUE = """\
import os, signal, sys, time
from vtool.app.cli.main import install_signal_handlers

install_signal_handlers()


def hold(seconds=0.3):
    os.kill(os.getpid(), signal.SIGINT)
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        pass


"""
EPILOGUE = """
try:
    inside()
    time.sleep(3.0)  # the interrupt, delivered again, arrives here
    sys.exit(0)
except KeyboardInterrupt:
    print("interrupted: nothing was written", file=sys.stderr)
    sys.exit(130)
"""
CASES = {
    "exec": """\
def inside():
    exec("hold()")
""",
    "llvmlite-callback": """\
import llvmlite.binding as llvm

def inside():
    llvm.initialize_native_target()
    llvm.initialize_native_asmprinter()
    machine = llvm.Target.from_default_triple().create_target_machine()
    engine = llvm.create_mcjit_compiler(llvm.parse_assembly("define i32 @f(i32 %x) {\\n  ret i32 %x\\n}\\n"), machine)
    engine.set_object_cache(lambda module, data: hold(), lambda module: None)
    engine.finalize_object()  # LLVM calls the notify callback (through ctypes) with the object code
""",
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_ctrl_c_inside_code_that_cannot_unwind_it_still_exits_130_with_one_line(case: str, tmp_path: Path) -> None:
    (tmp_path / "interrupted_here.py").write_text(PROLOGUE + CASES[case] + EPILOGUE)
    done = subprocess.run([sys.executable, "-m", "interrupted_here"], cwd=tmp_path, capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 130, done.stderr  # -2 (exec) or 0 (callback) with Python's own handler
    assert done.stderr == "interrupted: nothing was written\n"


def test_an_interrupt_waits_while_a_cache_file_is_written(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """numba writes a cache file as NAME.tmp.ID and renames it when whole; an interrupt while this process
    holds one open is delivered again later (the file would be left half-written), at once otherwise."""
    import inspect
    import signal

    from vtool import numba_cache
    from vtool.app.cli import main

    folder = tmp_path / "kernels-0123"
    folder.mkdir()
    monkeypatch.setattr(numba_cache, "FOLDER", folder)
    again: list[int] = []
    monkeypatch.setattr(main, "deliver_again", again.append)
    monkeypatch.setattr(main, "_held_back", lambda frame: False)  # (a pytest-xdist worker runs exec'd source)
    frame = inspect.currentframe()
    with open(folder / "step.layer_step-1.py311.1.nbc.tmp.0123456789abcdef", "wb"):
        assert main._writing_cache()
        main._interrupt(signal.SIGINT, frame)  # held back: no KeyboardInterrupt here
    assert again == [signal.SIGINT] and not main._writing_cache()
    for elsewhere in (tmp_path / "kernels-01234" / "a.nbc.tmp.0123", tmp_path / "b.nbc.tmp.0123"):
        elsewhere.parent.mkdir(exist_ok=True)
        with open(elsewhere, "wb"):  # a temporary file outside the cache folder: at once
            assert not main._writing_cache()
            with pytest.raises(KeyboardInterrupt):
                main._interrupt(signal.SIGINT, frame)
