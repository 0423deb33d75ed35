"""One dispatcher (issue 36): the kinds table is the only place that maps a preset kind to code, and
no module outside the back-end registry and the back ends' own packages names a back end.

Both are read from the source (Python's ``ast``), so a new ``if spec.kind == "plate"`` or
``backend="newmark"`` anywhere fails here with its file and line.
"""

from __future__ import annotations

import ast
from collections.abc import Iterator
from functools import cache
from pathlib import Path

from vtool.presets.kinds import KINDS, resolve
from vtool.solvers import backends

ROOT = Path(__file__).resolve().parent.parent
FOLDERS = ("app", "presets", "solvers", "assessments", "vtool")

#: a loader module parses its own kind(s) (the boom loader builds walls or floors): named by the table
LOADERS = {f"{kind.loader.replace('vtool.', '').replace('.', '/')}.py" for kind in KINDS.values()}
#: where a back end may be named: the registry, the back ends' packages
BACKEND_HOMES = ("solvers/backends.py", *(f"solvers/{name}/" for name in ("newmark", "exact", "scipy")))
#: the word of a back end's name used for something else: (file, word, what it means there)
OTHER_MEANINGS = {
    ("assessments/sonic_boom/spec.py", "exact"): "the exact pseudo-height rule of a boom wall",
    ("presets/boom.py", "exact"): "the exact pseudo-height rule of a boom wall",
    ("app/tui/boom.py", "exact"): "the exact pseudo-height rule of a boom wall",
    ("assessments/plate/report.py", "exact"): "the plate's exact (Navier) solution",
    ("app/tui/plate.py", "exact"): "the plate's exact (Navier) solution",
    ("app/cli/plate.py", "exact"): "the plate's exact (Navier) solution",
    ("presets/charts.py", "exact"): "the plate's exact (Navier) solution, a curve label",
    ("presets/report.py", "exact"): "the plate's exact (Navier) solution, a key of its study's dict",
    ("solvers/model/spec.py", "newmark"): "DEFAULT_BACKEND, re-exported as backends.DEFAULT",
    ("vtool/numba_cache.py", "newmark"): "the folder of the compiled kernel's sources (issue 35 reworks it)",
}
#: the contact problem's event rules and the result's buffers call the Newmark kernel's compiled fast
#: path and read its buffer layout (issue 35 reworks these; the contract is ContactProblem's methods)
KERNEL_USERS = {"solvers/model/contact.py", "solvers/trace.py"}


@cache
def parsed() -> tuple[tuple[str, ast.Module], ...]:
    return tuple((path.relative_to(ROOT).as_posix(), ast.parse(path.read_text(encoding="utf-8")))
                 for folder in FOLDERS for path in sorted((ROOT / folder).rglob("*.py")))


def sources() -> Iterator[tuple[str, ast.Module]]:
    yield from parsed()


def strings(node: ast.AST) -> Iterator[ast.Constant]:
    """The string constants under ``node`` that are not docstrings."""
    docstrings = set()
    for holder in ast.walk(node):
        body = getattr(holder, "body", None)
        if isinstance(body, list) and body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
            docstrings.add(id(body[0].value))
    for item in ast.walk(node):
        if isinstance(item, ast.Constant) and isinstance(item.value, str) and id(item) not in docstrings:
            yield item


def test_the_sources_are_read() -> None:
    files = dict(sources())
    assert "app/cli/solve.py" in files and "presets/kinds.py" in files and len(files) > 100


def test_only_the_kinds_table_compares_a_preset_kind() -> None:
    found = []
    for file, tree in sources():
        if file == "presets/kinds.py" or file in LOADERS:
            continue
        for node in ast.walk(tree):
            if isinstance(node, ast.Compare):
                named = [s.value for part in (node.left, *node.comparators) for s in strings(part)
                         if s.value in KINDS]
                if named:
                    found.append(f"{file}:{node.lineno} compares with {named}")
    assert found == [], "dispatch on a preset kind outside presets/kinds.py:\n" + "\n".join(found)


def test_the_kinds_docstring_table_is_the_table() -> None:
    import vtool.presets.kinds as kinds

    lines = (kinds.__doc__ or "").splitlines()
    rules = [i for i, line in enumerate(lines) if line.startswith("==========")]
    rows = [line.split() for line in lines[rules[1] + 1:rules[2]]]
    assert rows == [[k.name, k.spec_type, k.loader, k.solve, k.screen] for k in KINDS.values()]


def test_the_tui_finds_every_screen_through_the_kinds_table() -> None:
    from vtool.app.tui.app import SCREENS_BY_MODE, mode_for_kind

    for name, kind in KINDS.items():
        screen = resolve(kind.screen).SCREEN
        assert SCREENS_BY_MODE[mode_for_kind(name)] is screen


def test_no_module_outside_the_registry_names_a_back_end() -> None:
    names = set(backends.available())
    assert {"newmark", "exact", "scipy"} <= names
    packages = tuple(f"vtool.solvers.{name}" for name in ("newmark", "exact", "scipy"))
    found = []
    for file, tree in sources():
        if file.startswith(BACKEND_HOMES):
            continue
        for constant in strings(tree):
            if constant.value in names and (file, constant.value) not in OTHER_MEANINGS:
                found.append(f"{file}:{constant.lineno} names {constant.value!r}")
        for node in ast.walk(tree):
            modules = ([alias.name for alias in node.names] if isinstance(node, ast.Import)
                       else [node.module or ""] if isinstance(node, ast.ImportFrom) else [])
            for module in modules:
                if module.startswith(packages) and file not in KERNEL_USERS:
                    found.append(f"{file}:{node.lineno} imports {module}")
    assert found == [], "back ends named outside the registry:\n" + "\n".join(found)


def test_the_registry_answers_by_flags() -> None:
    assert backends.with_flag("reference") == ["exact"]
    assert backends.with_flag("fixed_step") == ["newmark"]
    assert backends.DEFAULT in backends.available()
    assert backends.module_of(backends.DEFAULT) == "vtool.solvers.newmark.backend"
