"""Test-session settings.

``VTOOL_KERNEL=compiled``: every run in the tests (and in the processes they
start) compiles the Newmark kernel in-process, or loads it from numba's cache,
before its first step, so that each test runs the compiled kernel it means to
test and no background compile competes with the suite for the CPU. The first
run's other paths (``auto``, ``plain``) have their own tests, which set the
variable themselves (tests/test_first_run.py).

``VTOOL_NATIVE=0``: no run builds or uses the kernel's native module
(:mod:`vtool.solvers.kernel_native`), so that a test in ``auto`` mode starts no
native build in the background; the native module's own tests set it to 1.
"""

import os

os.environ["VTOOL_KERNEL"] = "compiled"
os.environ["VTOOL_NATIVE"] = "0"
