"""No dead functions (issue 36): every function the product defines is named somewhere in the product,
the tests or the benchmarks, besides its own definition.

A name counts as used where it appears as a name, an attribute or a word in a string (a dotted path
the kinds table resolves, an entry point). Functions a framework calls by their name or decorator are
not counted as dead: decorated ones (click commands, Textual ``@on`` handlers, properties), Textual's
``on_*``/``action_*``/``watch_*`` handlers and the overrides named in :data:`HOOKS`.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PRODUCT = ("app", "presets", "solvers", "assessments", "vtool")
#: methods a library calls by name (click's MultiCommand, Textual's App/Screen/Message)
HOOKS = {"check_action", "can_replace", "list_commands", "get_command"}
FRAMEWORK = re.compile(r"^(on|action|watch)_|^__\w+__$")


def test_every_function_is_used() -> None:
    product = [path for folder in PRODUCT for path in (ROOT / folder).rglob("*.py")]
    others = [*(ROOT / "tests").rglob("*.py"), *(ROOT / "benchmarks").rglob("*.py")]
    used: set[str] = set()
    defined: list[tuple[str, int, str]] = []
    for path in [*product, *others]:
        tree = ast.parse(path.read_text(encoding="utf-8"))
        in_product = not path.is_relative_to(ROOT / "tests") and not path.is_relative_to(ROOT / "benchmarks")
        for node in ast.walk(tree):
            if isinstance(node, ast.Name):
                used.add(node.id)
            elif isinstance(node, ast.Attribute):
                used.add(node.attr)
            elif isinstance(node, ast.alias):
                used.add(node.name.rpartition(".")[2])
            elif isinstance(node, ast.Constant) and isinstance(node.value, str):
                used.update(re.findall(r"[A-Za-z_]\w*", node.value))
            elif (in_product and isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef)
                  and not node.decorator_list and not FRAMEWORK.search(node.name) and node.name not in HOOKS):
                defined.append((path.relative_to(ROOT).as_posix(), node.lineno, node.name))
    assert len(defined) > 500  # the product was read
    dead = [f"{path}:{line} {name}" for path, line, name in defined if name not in used]
    assert dead == [], "functions nothing calls:\n" + "\n".join(dead)
