"""The import graph of the installed package has no circle, lazy or not (issue 36).

The graph is grimp's (the library under import-linter) over the installed
layout (:mod:`tests.typing_tree`), with every import counted: at the top of a
module, inside a function (lazy) and under ``TYPE_CHECKING``. A circle is an
edge ``a -> b`` for which a chain ``b -> ... -> a`` exists.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from tests import typing_tree

pytestmark = pytest.mark.xdist_group("typing")

#: Circles being removed elsewhere, each named by the edge that closes it; the test also fails once one
#: of them is gone, so that its line is deleted here.
KNOWN: set[tuple[str, str]] = set()

SCRIPT = """
import json, sys
import grimp
graph = grimp.build_graph("vtool")
edges = sorted((a, b) for a in graph.modules if a.startswith("vtool")
               for b in graph.find_modules_directly_imported_by(a) if b.startswith("vtool") and b != a)
circles = [(a, b) for a, b in edges if graph.chain_exists(importer=b, imported=a)]
print(json.dumps({"edges": len(edges), "circles": circles}))
"""


def import_graph(tree: Path) -> dict[str, object]:
    import json

    result = subprocess.run([sys.executable, "-c", SCRIPT], cwd=tree, env=typing_tree.tool_env(tree),
                            capture_output=True, text=True, check=True)
    return json.loads(result.stdout)  # type: ignore[no-any-return]  # the script prints one JSON object


def test_no_import_circle(tmp_path: Path) -> None:
    graph = import_graph(typing_tree.build(tmp_path))
    assert int(graph["edges"]) > 300  # type: ignore[call-overload]  # the graph was read, not empty
    circles = {tuple(edge) for edge in graph["circles"]}  # type: ignore[attr-defined]
    assert circles - KNOWN == set(), "import circles (importer, imported):\n" + "\n".join(
        f"  {a} -> {b}" for a, b in sorted(circles - KNOWN))
    assert KNOWN <= circles, f"no longer circles, delete from KNOWN: {sorted(KNOWN - circles)}"
