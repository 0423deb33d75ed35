"""The kernel's native module (:mod:`vtool.solvers.newmark.native`): built in the background after the
first compile, then used by every default-mode run, which imports no numba and gets the JIT kernel's
results to the last bit."""

from __future__ import annotations

import io
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from tests.test_first_run import needs_jit, wait_until_cached
from vtool.presets import load_preset
from vtool.presets.valvetrain import with_run_overrides
from vtool.solvers.newmark import kernel
from vtool.solvers.newmark import layout as kernel_layout
from vtool.solvers.newmark import native as kernel_native
from vtool.solvers.run import simulate

# one worker, scheduled first with the other groups (see conftest.py): two native builds, 40-65 s
pytestmark = pytest.mark.xdist_group("native")


def test_the_kernel_names_the_layout_it_was_written_for() -> None:
    """numba's cache is stamped by newmark_kernel.py alone: an edit of kernel_layout.py must change that file
    too (update LAYOUT_FINGERPRINT to the value below), or cached kernels would keep the old slots."""
    assert kernel.LAYOUT_FINGERPRINT == kernel_layout.fingerprint()


def test_the_module_name_follows_the_argument_types_and_switches() -> None:
    a = (np.zeros(3), np.zeros((2, 2), dtype=np.int64), None, None)
    name = kernel_native.module_name(a)
    assert name.startswith("vtool_native_h0m0_")
    assert kernel_native.module_name((np.zeros(4), np.ones((3, 3), dtype=np.int64), None, None)) == name  # shapes: no
    assert kernel_native.module_name((np.zeros(3), np.zeros((2, 2)), None, None)) != name  # dtype
    assert kernel_native.module_name((np.zeros((3, 1)), a[1], None, None)) != name  # dimensions
    assert kernel_native.module_name((np.zeros((3, 2)).T[0], a[1], None, None)) != name  # layout
    readonly = np.zeros(3)
    readonly.flags.writeable = False
    assert kernel_native.module_name((readonly, a[1], None, None)) != name
    assert kernel_native.module_name((*a[:2], True, None)).startswith("vtool_native_h1m0_")
    assert kernel_native.module_name((*a[:2], None, True)).startswith("vtool_native_h0m1_")


def test_the_kept_module_names_are_those_the_types_give() -> None:
    """module_name keeps its names by a cheaper key than type_key's text: the name is always the one the
    text gives, and arrays whose texts differ (alignment, byte order, layout, writeability) never share it,
    in whatever order they come; a view and its owner (owning its data is not a type) share it."""
    base = np.zeros(8)
    unaligned = np.ndarray(8, dtype=np.float64, buffer=bytearray(65), offset=1)
    readonly = np.zeros(8)
    readonly.flags.writeable = False
    variants = [base, base[:4], np.zeros((8, 1))[:, 0], unaligned, np.zeros(8, dtype=">f8"), readonly,
                np.zeros((2, 4), order="F"), np.zeros((2, 4)), np.zeros((4, 4))[:, ::2], np.zeros(8, dtype=np.int64)]
    assert not unaligned.flags.aligned and base[:4].flags.owndata is False
    for order in (variants, variants[::-1]):
        for value in order:
            values = (value, None, None)
            expected = (f"{kernel_native.PREFIX}h0m0_{kernel_native._digest(kernel_native._environment())}_"
                        f"{kernel_native._digest(kernel_native.type_key(values))}")
            assert kernel_native.module_name(values) == expected
    texts = {kernel_native.type_key((v,)) for v in variants}
    assert len({kernel_native.module_name((v, None, None)) for v in variants}) == len(texts) == len(variants) - 2


@needs_jit
def test_a_run_names_the_kernel_that_ran_it(monkeypatch) -> None:  # noqa: ANN001
    assert simulate(load_preset("gnilka-1a")).statistics.kernel == "numba"  # the tests' mode: compiled
    monkeypatch.setenv("VTOOL_KERNEL", "plain")
    short = with_run_overrides(load_preset("gnilka-1a"), degrees=20.0)
    assert simulate(short).statistics.kernel == "plain"
    exact = with_run_overrides(short, backend="exact")
    assert simulate(exact).statistics.kernel == ""  # (the piecewise back ends call only the event rules)


def test_no_module_is_used_when_turned_off(monkeypatch, tmp_path) -> None:  # noqa: ANN001
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    monkeypatch.setenv("VTOOL_NATIVE", "0")
    assert not kernel_native.enabled() and not kernel_native.exists((None, None))
    assert kernel_native.load((np.zeros(1), None, None)) is None
    monkeypatch.setenv("VTOOL_NATIVE", "1")
    monkeypatch.setenv("NUMBA_DISABLE_JIT", "1")
    assert not kernel_native.enabled()


def test_the_csv_writer_is_chosen_without_numba_when_it_can_be(monkeypatch) -> None:  # noqa: ANN001
    from vtool import csvrows

    def native(*args):  # noqa: ANN002, ANN202
        raise AssertionError("not called")

    assert csvrows.choose(10, None, native) is native
    assert csvrows.choose(10**6, None, native) is native
    assert csvrows.choose(10**6, True, native) is native
    assert csvrows.choose(10, False, native) is None  # Python's formatting asked for
    monkeypatch.delitem(sys.modules, "numba", raising=False)  # (put back after the test)
    assert csvrows.choose(10, None) is None  # small, numba not loaded: Python's, numba not imported for it


def test_a_damaged_module_is_not_loaded(monkeypatch, tmp_path) -> None:  # noqa: ANN001
    """A file that will not load (truncated, foreign) leaves the run on numba's cache: load gives None."""
    monkeypatch.setenv("VTOOL_NATIVE", "1")
    monkeypatch.setattr(kernel_native, "folder", lambda: tmp_path)
    values = (np.zeros(2), None, None)
    kernel_native.path(kernel_native.module_name(values)).write_bytes(b"not a shared object")
    assert kernel_native.exists((None, None))
    assert kernel_native.load(values) is None


RUN_NATIVE = """
import contextlib, io, sys
import numpy as np
from vtool.app.cli.main import main
from vtool.presets import load_preset
from vtool.presets.valvetrain import with_run_overrides
from vtool.solvers.run import simulate
trace = simulate(load_preset("gnilka-1a"))
np.savez(sys.argv[1], time=trace.time, q=trace.q, qd=trace.qd, qdd=trace.qdd, force=trace.contact_force,
         configuration=trace.configuration, peak=trace.peak_force)
sys.argv = ["vtool", "solve", "gnilka-1a", "--csv", sys.argv[2]]
try:
    with contextlib.redirect_stdout(io.StringIO()):
        main()
except SystemExit as exc:
    assert exc.code in (0, None), exc.code
assert "numba" not in sys.modules, "numba was imported"
"""


BUNDLED_PROBE = """
from vtool import numba_link
from vtool.solvers.newmark import kernel
types = kernel.cached_signatures("run_chunk")[0]
kernel.run_chunk.compile(types)
library = kernel.run_chunk.overloads[tuple(types)].library
print("bundled" if getattr(library, numba_link.BUNDLE, None) is not None else "linked")
"""


@needs_jit
@pytest.mark.slow
def test_a_new_install_runs_at_once_then_compiled_then_native(tmp_path) -> None:  # noqa: ANN001
    """Empty cache, the default mode: the first ``vtool solve`` announces the background compile and runs as
    plain Python; the child fills numba's cache (``run_chunk`` with its callees' bundle, see
    vtool.numba_link), then builds the native module; the next run is compiled
    and silent, loads the native module, imports no numba and equals the JIT kernel's run to the last bit;
    ``vtool solve --csv`` writes Python's text with the module's formatter, numba still not imported."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"), VTOOL_NATIVE="1")
    env.pop("VTOOL_KERNEL")
    first = subprocess.run([sys.executable, "-m", "vtool", "solve", "gnilka-1a", "--json"], env=env,
                           capture_output=True, text=True, timeout=600)
    assert first.returncode == 0, first.stderr
    assert "in the background" in first.stderr
    summary = json.loads(first.stdout)
    assert summary["plain_steps"] > 0 and summary["compile_time_s"] < 5.0
    assert summary["kernel"] in ("plain", "numba")  # numba if the compile finished before the run did
    wait_until_cached(env, ("run_chunk",))
    bundled = subprocess.run([sys.executable, "-c", BUNDLED_PROBE], env=env, capture_output=True, text=True,
                             timeout=600)
    assert bundled.stdout.strip() == "bundled", bundled.stderr  # the child's compile made its callees' bundle
    probe = "import sys; from vtool.solvers.newmark import native as k; sys.exit(0 if k.exists((None, None)) else 1)"
    deadline = time.monotonic() + 600
    while subprocess.run([sys.executable, "-c", probe], env=env).returncode != 0:
        assert time.monotonic() < deadline, "no native module 600 s after the first run"
        time.sleep(1.0)
    second = subprocess.run([sys.executable, "-m", "vtool", "solve", "gnilka-1a", "--json"], env=env,
                            capture_output=True, text=True, timeout=600)
    assert second.returncode == 0, second.stderr
    assert "compiling" not in second.stderr
    again = json.loads(second.stdout)
    assert again["plain_steps"] == 0 and again["compile_time_s"] == 0.0 and again["kernel"] == "native"
    assert again["events_list"] == summary["events_list"]
    saved, csv = tmp_path / "native.npz", tmp_path / "native.csv"
    run = subprocess.run([sys.executable, "-c", RUN_NATIVE, str(saved), str(csv)], env=env, capture_output=True,
                         text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    native = np.load(saved)
    jit = simulate(load_preset("gnilka-1a"))  # this process: VTOOL_KERNEL=compiled, numba's JIT kernel
    for name, value in (("time", jit.time), ("q", jit.q), ("qd", jit.qd), ("qdd", jit.qdd),
                        ("force", jit.contact_force), ("configuration", jit.configuration), ("peak", jit.peak_force)):
        np.testing.assert_array_equal(native[name], value, err_msg=name)
    python = io.StringIO()
    jit.write_csv_to(python, jit.spec.run.quantities, compiled=False)  # Python's own '%.10g'
    assert csv.read_text() == python.getvalue()  # the native module's CSV writer, same text


@needs_jit
@pytest.mark.slow
def test_a_hertz_contact_runs_on_its_own_module_to_the_last_bit(monkeypatch, tmp_path) -> None:  # noqa: ANN001
    """The Hertz switch is an argument type (see kernel_layout.laws): its module is another one, built with
    the Hertz iteration, and equal to the JIT kernel's run bit for bit (the drop test on a Hertz seat)."""
    from tests.test_compliant import hertz_doc
    from tests.valvetrain_cases import spec_from
    from vtool.solvers.model.contact import ContactProblem
    from vtool.solvers.model.mechanism import assemble
    from vtool.solvers.newmark.backend import KernelRun, NewmarkOptions
    from vtool.solvers.trace import TraceBuilder

    spec = spec_from(hertz_doc())
    jit = simulate(spec)  # the tests' mode: numba's kernel
    mechanism = assemble(spec)
    problem = ContactProblem(mechanism)
    run = KernelRun(problem, NewmarkOptions.from_run(spec.run), TraceBuilder(spec, problem.source_numbers,
                                                                              problem.omega))
    monkeypatch.setattr(kernel_native, "folder", lambda: tmp_path)
    monkeypatch.setenv("VTOOL_NATIVE", "1")
    name = kernel_native.module_name(run.arguments())
    assert name.startswith("vtool_native_h1m0_")
    kernel_native.build(name, run.signature)
    assert kernel_native.exists((True, None)) and not kernel_native.exists((None, None))
    monkeypatch.setenv("VTOOL_KERNEL", "auto")
    native = simulate(spec)
    assert native.statistics.kernel == "native"
    assert len(native.events) == len(jit.events)
    for name in ("time", "q", "qd", "qdd", "contact_force", "configuration", "peak_force", "peak_overlap"):
        np.testing.assert_array_equal(getattr(native, name), getattr(jit, name), err_msg=name)


def test_the_digest_reads_the_files_the_module_is_built_from() -> None:
    from vtool import csvrows

    files = kernel_native.sources()
    assert all(file.is_file() for file in files)
    assert {file.name for file in files} == {"kernel.py", "layout.py", "csvrows_kernel.py",
                                              "native.py"}
    assert files[0] == Path(kernel.__file__).resolve()
    assert files[2].parent == Path(csvrows.__file__).parent  # beside the CSV writer, whatever the install


@needs_jit
def test_a_failed_native_build_is_not_asked_again_by_every_run(monkeypatch) -> None:  # noqa: ANN001
    """Default mode, the kernel in numba's cache, its native module's build failed (no C compiler, say):
    the first run finds the failure, later runs of the process go on numba's kernel without asking."""
    from vtool.solvers.newmark import backend as newmark
    from vtool.solvers.newmark import build as kernel_build

    asked: list[list] = []

    def start(jobs: list) -> bool:
        asked.append(jobs)
        return False  # as start() answers when the build's failure note is there

    monkeypatch.setenv("VTOOL_KERNEL", "auto")
    monkeypatch.setenv("VTOOL_NATIVE", "1")
    monkeypatch.setattr(kernel_native, "load", lambda values: None)  # no module built
    monkeypatch.setattr(kernel_build, "start", start)
    monkeypatch.setattr(newmark, "_no_native_build", set())
    short = with_run_overrides(load_preset("gnilka-1a"), degrees=2.0)
    runs = [simulate(short) for _ in range(3)]
    assert [run.statistics.kernel for run in runs] == ["numba"] * 3
    assert len(asked) == 1 and [job[0] for job in asked[0]] == ["native"]
    other = with_run_overrides(load_preset("gnilka-2"), degrees=2.0)  # the same module (same argument types)
    assert simulate(other).statistics.kernel == "numba" and len(asked) == 1
