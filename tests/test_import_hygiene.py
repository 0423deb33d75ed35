"""Layering: nothing below app/ imports textual, plotext or click (STYLE.md)."""

from __future__ import annotations

import subprocess
import sys

import pytest

HEADLESS = [
    "vtool.solvers",
    "vtool.assessments",
    "vtool.presets",
    "vtool.errors",
    "vtool.files",
]


@pytest.mark.parametrize("module", HEADLESS)
def test_headless_module_imports_no_ui(module: str) -> None:
    code = (
        "import importlib, pkgutil, sys\n"
        f"pkg = importlib.import_module({module!r})\n"
        "for info in pkgutil.walk_packages(getattr(pkg, '__path__', []), pkg.__name__ + '.'):\n"
        "    importlib.import_module(info.name)\n"
        "bad = [m for m in ('textual', 'plotext', 'click') if m in sys.modules]\n"
        "print(','.join(bad))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "", f"{module} pulls in {out.stdout.strip()}"


def test_no_bare_top_level_packages() -> None:
    """The installed code lives under `vtool` only, never as bare `app` or `solvers`."""
    import importlib.util

    import vtool.solvers

    for bare in ("app", "solvers", "assessments", "presets"):
        spec = importlib.util.find_spec(bare)
        if spec is not None and spec.origin:
            assert "site-packages" not in spec.origin, f"bare {bare} installed"
    assert vtool.solvers.__name__ == "vtool.solvers"


def test_cli_help_imports_no_numerics() -> None:
    code = (
        "import sys\nfrom click.testing import CliRunner\n"
        "from vtool.app.cli.main import cli\n"
        "r = CliRunner().invoke(cli, ['--help'])\n"
        "assert r.exit_code == 0, r.output\n"
        "print(','.join(m for m in ('numba', 'scipy', 'textual') if m in sys.modules))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == ""
