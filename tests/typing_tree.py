"""The installed layout of `vtool` as a plain folder, for tools that cannot follow package-dir.

pyproject maps the repository folders into one package (``solvers/`` is
``vtool.solvers``); an editable install does this with an import hook that
mypy and import-linter (grimp) do not see, and both walk real folders. So
:func:`build` copies the sources into ``build/typing/vtool`` with the
installed layout (``vtool/``, ``vtool/app``, ``vtool/solvers``,
``vtool/presets``, ``vtool/assessments``), and the tools run on that copy with
``build/typing`` first on their path. Run ``python tests/typing_tree.py`` to
build it and run both tools as the tests do (docs/typing.md).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
TREE = ROOT / "build" / "typing"
FOLDERS = {"app": "app", "solvers": "solvers", "presets": "presets", "assessments": "assessments"}


def build(tree: Path = TREE) -> Path:
    """Copy the sources into ``tree/vtool`` (the installed layout); returns ``tree``."""
    package = tree / "vtool"
    if package.exists():
        shutil.rmtree(package)
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc", "*.nbi", "*.nbc")
    shutil.copytree(ROOT / "vtool", package, ignore=ignore)
    for name, folder in FOLDERS.items():
        shutil.copytree(ROOT / folder, package / name, ignore=ignore)
    return tree


def tool_env(tree: Path = TREE) -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(tree), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    env["MYPYPATH"] = str(tree)
    return env


#: what mypy checks: the whole installed package
MYPY_TARGETS = ("-p", "vtool")


def run_mypy(tree: Path = TREE) -> subprocess.CompletedProcess[str]:
    """mypy on the whole vtool package with pyproject's configuration."""
    return subprocess.run(
        [sys.executable, "-m", "mypy", "--config-file", str(ROOT / "pyproject.toml"),
         "--cache-dir", str(ROOT / ".mypy_cache"), *MYPY_TARGETS],
        cwd=tree, env=tool_env(tree), capture_output=True, text=True, check=False)


def run_lint_imports(tree: Path = TREE) -> subprocess.CompletedProcess[str]:
    """import-linter's contracts (pyproject) on the installed layout."""
    script = Path(sys.executable).with_name("lint-imports")
    command = [str(script)] if script.exists() else ["lint-imports"]
    return subprocess.run([*command, "--config", str(ROOT / "pyproject.toml")], cwd=tree,
                          env=tool_env(tree), capture_output=True, text=True, check=False)


if __name__ == "__main__":
    build()
    for result in (run_lint_imports(), run_mypy()):
        print(result.stdout + result.stderr)
