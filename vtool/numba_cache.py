"""Where numba caches compiled kernels, so a read-only install still runs.

numba writes its cache beside the module (``__pycache__``) or, when that
folder is read-only, in the user cache folder. When neither is writable every
``@njit(cache=True)`` function fails at import with ``RuntimeError: cannot
cache function ... no locator available``. :func:`configure` runs before numba
is imported (the kernel module calls it first) and:

1. keeps ``NUMBA_CACHE_DIR`` when the user set it;
2. otherwise keeps numba's default when the package folder is writable;
3. otherwise points ``NUMBA_CACHE_DIR`` at the first writable folder of
   ``$XDG_CACHE_HOME/vtool/numba``, ``~/.cache/vtool/numba`` and
   ``<tempdir>/vtool-numba-<uid>``;
4. and when none is writable, disables caching (``NUMBA_DISABLE_CACHE``-like:
   :data:`CACHE_ENABLED` is False, the kernel module passes it as ``cache=``)
   with a one-line warning on stderr: every run then compiles again.

It also answers numba's start-up BLAS probe (:func:`decline_blas_probe`).
"""

from __future__ import annotations

import importlib.abc
import os
import sys
import tempfile
from pathlib import Path

#: False when no writable cache folder was found (compile on every start).
CACHE_ENABLED = True
_configured: str | None = None


def _writable(folder: Path) -> bool:
    try:
        folder.mkdir(parents=True, exist_ok=True)
        probe = tempfile.NamedTemporaryFile(dir=folder, prefix=".probe.", delete=True)
        probe.close()
    except OSError:
        return False
    return True


def candidates() -> list[Path]:
    """Cache folders tried in order when the package folder is read-only."""
    xdg = os.environ.get("XDG_CACHE_HOME")
    folders = [Path(xdg) / "vtool" / "numba"] if xdg else []
    folders.append(Path.home() / ".cache" / "vtool" / "numba")
    uid = os.getuid() if hasattr(os, "getuid") else "user"
    folders.append(Path(tempfile.gettempdir()) / f"vtool-numba-{uid}")
    return folders


def configure(package_dir: str | os.PathLike[str] | None = None) -> str:
    """Choose the numba cache folder (see module doc); returns what was chosen, in words.

    ``package_dir`` is the folder of the kernel module (default: ``vtool/solvers``).
    Idempotent: a second call returns the first answer.
    """
    global CACHE_ENABLED, _configured
    if _configured is not None:
        return _configured
    decline_blas_probe()
    if os.environ.get("NUMBA_CACHE_DIR"):
        _configured = f"NUMBA_CACHE_DIR={os.environ['NUMBA_CACHE_DIR']} (set by the user)"
        return _configured
    here = Path(package_dir) if package_dir else Path(__file__).resolve().parent.parent / "solvers" / "newmark"
    if os.access(here, os.W_OK) and _writable(here / "__pycache__"):
        _configured = f"numba default (beside the package, {here / '__pycache__'})"
        return _configured
    for folder in candidates():
        if _writable(folder):
            os.environ["NUMBA_CACHE_DIR"] = str(folder)
            _reload_numba_config()
            _configured = f"NUMBA_CACHE_DIR={folder}"
            return _configured
    CACHE_ENABLED = False
    os.environ["NUMBA_CACHE_DIR"] = str(Path(tempfile.gettempdir()))  # never written: cache=False
    _configured = "caching disabled (no writable folder)"
    print("warning: no writable folder for numba's cache; kernels are compiled on every start "
          "(set NUMBA_CACHE_DIR to a writable folder)", file=sys.stderr)
    return _configured


def _reload_numba_config() -> None:
    """numba reads its environment at import: re-read it when numba came first."""
    if "numba" in sys.modules:
        from numba.core import config

        config.reload_config()


class _BlasProbe(importlib.abc.MetaPathFinder):
    """Refuses ``scipy.linalg`` to numba's start-up probe ``numba.np.arraymath._check_blas`` only."""

    def find_spec(self, name, path=None, target=None):  # type: ignore[no-untyped-def]  # noqa: ANN001, ANN201
        if name != "scipy.linalg":
            return None
        frame = sys._getframe(1)
        while frame is not None:
            if frame.f_code.co_name == "_check_blas" and frame.f_globals.get("__name__") == "numba.np.arraymath":
                raise ImportError("vtool: numba's BLAS probe declined (vtool's kernels use no BLAS)")
            frame = frame.f_back
        return None


def decline_blas_probe() -> None:
    """Keep numba's start-up from importing ``scipy.linalg`` (0.15-0.25 s of every process).

    When numba first loads a compiled function it imports ``numba.np.arraymath``,
    whose module code probes for BLAS by importing ``scipy.linalg.cython_blas``
    and keeps the answer only to choose between BLAS and a plain loop in
    ``np.correlate``/``np.convolve``, which vtool's kernels do not call. This
    finder makes that one probe fail, so a ``vtool solve`` that needs no scipy
    loads none of ``scipy.linalg``. Every other import of ``scipy.linalg`` (the
    exact and scipy back ends, numba typing ``np.linalg`` or ``np.dot``, which
    call ``ensure_blas`` themselves) goes through unchanged. Idempotent.
    """
    if not any(isinstance(finder, _BlasProbe) for finder in sys.meta_path):
        sys.meta_path.insert(0, _BlasProbe())
