"""The first run and numba's cache: stock numba only, a checked cache folder, a visible compile.

* no file of the product imports a private numba name or builds an ahead-of-time module;
* the cache folder is used only when it is the user's own and not writable by others: a planted
  one is not used and nothing in it is loaded (a test plants pickles that would run a command);
* a first run says it compiles, with the last measured compile time once there is one; a pipe
  gets that one line and no progress; Ctrl+C during the compile exits cleanly (130) and leaves a
  cache the next run loads.
"""

from __future__ import annotations

import io
import json
import os
import pickle
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from vtool import jit, numba_cache
from vtool.solvers.newmark import kernel

ROOT = Path(__file__).resolve().parent.parent
PRODUCT = ("vtool", "solvers", "app", "presets", "assessments")
needs_jit = pytest.mark.skipif(not hasattr(kernel.run_chunk, "signatures"),
                               reason="NUMBA_DISABLE_JIT: nothing is compiled")
#: Private numba names: its internal modules, underscore attributes, undocumented options.
PRIVATE = re.compile(r"numba\.(core|pycc|np|misc|cpython|_\w+)\b|from numba import _|numba\._"
                     r"|\b_nrt\b|no_cpython_wrapper|no_cfunc_wrapper|\._cache\b|_load_index|\bpycc\b")


def product_files() -> list[Path]:
    return sorted(path for folder in PRODUCT for path in (ROOT / folder).rglob("*.py"))


def test_no_product_file_names_a_private_numba_module_or_attribute() -> None:
    found = [f"{path.relative_to(ROOT)}:{number}: {line.strip()}" for path in product_files()
             for number, line in enumerate(path.read_text().splitlines(), 1) if PRIVATE.search(line)]
    assert product_files() and found == []


def test_the_private_name_check_finds_what_it_looks_for() -> None:
    for line in ("from numba.core import config", "from numba.pycc import CC", "import numba.np.arraymath",
                 "njit(_nrt=False)", "f._cache._cache_file._load_index()", "from numba import _dynfunc"):
        assert PRIVATE.search(line), line
    for line in ("from numba import njit", "numba.typeof(x)", "numba.config.CACHE_DIR = folder"):
        assert not PRIVATE.search(line), line


def test_no_lock_files_and_no_switches_of_the_removed_machinery() -> None:
    text = "\n".join(path.read_text() for path in product_files())
    for name in ("VTOOL_NATIVE", "VTOOL_LINK_ONLY", "VTOOL_TYPING_MEMO", "VTOOL_KERNEL", ".lock"):
        assert name not in text, name


# ----- the cache folder -----
CHECK = """
import json, numpy as np
from vtool import numba_cache
from vtool.solvers.newmark import kernel
clf = np.zeros((1, 5)); clf[0, 2:5] = (1e7, 1.5, 1.0)
force = kernel.hertz_force(clf, 0, 1e-4, 0.0)[0]
print(json.dumps({"enabled": numba_cache.CACHE_ENABLED, "folder": str(numba_cache.FOLDER), "force": force}))
"""


class Planted:
    """A pickle that, when loaded, creates the file ``marker`` (what a planted numba index could do)."""

    def __init__(self, marker: Path) -> None:
        self.marker = marker

    def __reduce__(self):  # type: ignore[no-untyped-def]  # noqa: ANN204
        return (Path.touch, (self.marker,))


def plant(base: Path, marker: Path) -> int:
    """Copy this session's cache folder into ``base`` (same digest, so the same file names numba would
    read), every index and data file replaced by a :class:`Planted` pickle; returns the files planted."""
    assert numba_cache.FOLDER is not None
    target = base / numba_cache.FOLDER.name
    planted = 0
    for path in numba_cache.FOLDER.rglob("*"):
        if path.suffix in (".nbi", ".nbc"):
            copy = target / path.relative_to(numba_cache.FOLDER)
            copy.parent.mkdir(parents=True, exist_ok=True)
            copy.write_bytes(pickle.dumps(Planted(marker)))
            planted += 1
    return planted


@needs_jit
@pytest.mark.parametrize("how", ["owned by another user", "writable by others"])
def test_a_cache_folder_not_the_users_own_is_not_used_and_nothing_is_loaded(tmp_path: Path, how: str) -> None:
    if not numba_cache.CACHE_ENABLED or not hasattr(os, "getuid"):
        pytest.skip("no cache in this session (or no user ids)")
    clf = np.zeros((1, 5))
    clf[0, 2:5] = (1e7, 1.5, 1.0)
    expected = kernel.hertz_force(clf, 0, 1e-4, 0.0)[0]  # (compiled and cached in this session's folder)
    base, marker = tmp_path / "cache", tmp_path / "loaded"
    base.mkdir(mode=0o700)
    assert plant(base, marker) > 0
    if how == "owned by another user":
        if os.getuid() != 0:
            pytest.skip("changing a folder's owner needs root")
        for path in [base, *base.rglob("*")]:
            os.chown(path, 12345, 12345)
    else:
        base.chmod(0o777)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(base))
    out = subprocess.run([sys.executable, "-c", CHECK], capture_output=True, text=True, env=env, check=True)
    answer = json.loads(out.stdout)
    assert not answer["enabled"] and answer["folder"] == "None"
    assert answer["force"] == expected
    assert not marker.exists()  # nothing of the planted cache was loaded
    warning = out.stderr.strip()
    assert warning.count("\n") == 0 and warning.startswith("warning: numba's cache is off")
    assert str(base) in warning and ("another user" in warning if how.startswith("owned") else "writable" in warning)


def test_a_child_process_shares_its_parents_cache_folder(tmp_path: Path) -> None:
    """configure() exports BASE/kernels-DIGEST; a child (a sweep worker, a subprocess) inherits it and
    must cache in the same folder, not in BASE/kernels-DIGEST/kernels-DIGEST (empty: a whole compile
    again, 140 s for 1A measured at load 6.5)."""
    report = "from vtool import numba_cache; print(numba_cache.configure())"
    child = f"subprocess.run([sys.executable, '-c', {report!r}], capture_output=True, text=True).stdout"
    parent = f"{report}; import subprocess, sys; print({child})"
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    lines = subprocess.run([sys.executable, "-c", parent], capture_output=True, text=True, env=env,
                           check=True).stdout.split()
    name = f"kernels-{numba_cache.digest(numba_cache.kernel_sources())}"
    assert lines == [f"NUMBA_CACHE_DIR={tmp_path / 'cache' / name}"] * 2


@needs_jit
def test_a_safe_folder_is_used_with_the_kernels_digest_in_its_name(tmp_path: Path) -> None:
    base = tmp_path / "cache"
    env = dict(os.environ, NUMBA_CACHE_DIR=str(base))
    out = subprocess.run([sys.executable, "-c", CHECK], capture_output=True, text=True, env=env, check=True)
    answer = json.loads(out.stdout)
    folder = Path(answer["folder"])
    assert answer["enabled"] and out.stderr == "" and folder.parent == base
    assert folder.name == f"kernels-{numba_cache.digest(numba_cache.kernel_sources())}"
    assert (base.stat().st_mode & 0o777) == 0o700 and (folder.stat().st_mode & 0o777) == 0o700
    assert any(folder.rglob("*.nbi"))  # numba cached hertz_force there


def test_the_digest_follows_every_kernel_file(tmp_path: Path) -> None:
    """An edit of any kernel file (a callee in another file too) names another, empty folder."""
    files = []
    for name in ("caller.py", "callee.py"):
        path = tmp_path / name
        path.write_text("x = 1\n")
        files.append(path)
    before = numba_cache.digest(files)
    files[1].write_text("x = 2\n")
    assert numba_cache.digest(files) != before
    names = {path.name for path in numba_cache.kernel_sources()}
    assert {"jit.py", "csvrows_kernel.py", "layout.py", "records.py", "loop.py", "step.py", "impacts.py"} <= names


# ----- the first run -----
def test_the_notice_quotes_the_last_measured_compile(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(numba_cache, "BASE", tmp_path)
    assert "about 5-20 s on this machine" in jit.compile_notice("the solver", "run_chunk")
    numba_cache.record_compile("run_chunk", 7.4)
    assert jit.compile_notice("the solver", "run_chunk").startswith("compiling the solver once, about 7 s on "
                                                                       "this machine")
    assert json.loads((tmp_path / numba_cache.TIMES).read_text()) == {"run_chunk": 7.4}


@pytest.mark.parametrize(("before", "inside"), [
    ((700, 10, 10), (100_000, 50, 100)),  # Python's own: raised to the CLI's
    ((200_000, 5, 500), (200_000, 50, 500)),  # each threshold raised, never lowered
    ((0, 10, 10), (0, 10, 10)),  # collection turned off by the process: left off
])
def test_a_compile_raises_the_collector_thresholds_and_restores_them(before: tuple[int, int, int],
                                                                     inside: tuple[int, int, int]) -> None:
    """``jit.fewer_collections`` (around every compiling call, ``jit.timed_call``): the process' own thresholds
    restored after."""
    import gc

    kept = gc.get_threshold()
    try:
        gc.set_threshold(*before)
        with jit.fewer_collections():
            seen = gc.get_threshold()
        after = gc.get_threshold()
    finally:
        gc.set_threshold(*kept)
    assert seen == inside and after == before


def test_overlapping_compiles_restore_the_thresholds_when_the_last_ends() -> None:
    """Two threads compiling at once (a threaded sweep's first points): the first to end leaves the
    thresholds raised for the other, the last restores the process' own."""
    import gc

    kept = gc.get_threshold()
    try:
        gc.set_threshold(700, 10, 10)
        first, second = jit.fewer_collections(), jit.fewer_collections()
        first.__enter__()
        second.__enter__()
        first.__exit__(None, None, None)
        between = gc.get_threshold()
        second.__exit__(None, None, None)
        after = gc.get_threshold()
    finally:
        gc.set_threshold(*kept)
    assert between == jit.COMPILE_GC_THRESHOLDS and after == (700, 10, 10)


@pytest.mark.parametrize("given", [None, "yes"])
def test_numba_highlights_no_error_messages_unless_the_user_asks(given: str | None) -> None:
    """vtool sets numba's documented switch before numba is imported, and keeps a value the user set."""
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_DISABLE_ERROR_MESSAGE_HIGHLIGHTING"}
    if given is not None:
        env["NUMBA_DISABLE_ERROR_MESSAGE_HIGHLIGHTING"] = given
    script = ("import os, sys, vtool.jit; assert 'numba' in sys.modules; "
              "print(os.environ['NUMBA_DISABLE_ERROR_MESSAGE_HIGHLIGHTING'])")
    done = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True, check=True)
    assert done.stdout.strip() == (given or "1")


def test_elapsed_seconds_show_on_a_terminal_only(monkeypatch: pytest.MonkeyPatch) -> None:
    from vtool.app.cli.progress import DelayedProgress

    class Terminal(io.StringIO):
        def isatty(self) -> bool:
            return True

    for stream, shown in ((Terminal(), True), (io.StringIO(), False)):
        monkeypatch.setattr(sys, "stderr", stream)
        progress = DelayedProgress("newmark")
        progress.tick()
        time.sleep(1.3)
        progress(1.0)
        progress.close()
        assert ("compiling... 1 s" in stream.getvalue()) is shown


@needs_jit
@pytest.mark.slow
def test_a_first_run_announces_its_compile_and_ctrl_c_leaves_a_usable_cache(tmp_path: Path) -> None:
    """Empty cache: Ctrl+C during the compile exits 130 with one line, no traceback, no half-written
    file; then a run says it compiles (one line on a pipe, no progress), answers with 1A's 59 events
    and keeps its compile time, and the next process says nothing and loads it."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path))
    command = [sys.executable, "-m", "vtool", "solve", "gnilka-1a", "--json"]
    process = subprocess.Popen(command, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(4.0)  # the imports, then the compile
    process.send_signal(signal.SIGINT)
    stdout, stderr = process.communicate(timeout=120)
    # (130 only: an interrupt inside exec'd source or llvmlite's callback ended it by SIGINT, -2, or lost it,
    # now held back until it can unwind: tests/test_cli_signals.py)
    assert process.returncode == 130, stderr
    assert stderr.splitlines()[-1] == "interrupted: nothing was written" and "Traceback" not in stderr
    assert not [p for p in tmp_path.rglob("*") if ".tmp" in p.name or p.suffix == ".done"]
    first = subprocess.run(command, env=env, capture_output=True, text=True, check=True)
    assert first.stderr.splitlines() == [first.stderr.strip()]
    assert re.fullmatch(r"compiling the solver once, about (5-20|\d+) s on this machine; later runs load it "
                        r"from the cache", first.stderr.strip())
    assert len(json.loads(first.stdout)["events_list"]) == 59
    assert json.loads((tmp_path / numba_cache.TIMES).read_text())["run_chunk"] > 0
    second = subprocess.run(command, env=env, capture_output=True, text=True, check=True)
    assert second.stderr == "" and len(json.loads(second.stdout)["events_list"]) == 59
    shutil.rmtree(tmp_path, ignore_errors=True)
