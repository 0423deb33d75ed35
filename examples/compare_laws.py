"""Compare impact laws: the same train and step under each law of docs/contact.md.

Solves the preset once per impact law (``contact.impact``: local, thesis,
momentum) and prints, per law, the events, the separations and impacts at each
clearance and the peak contact forces, from the results' arrays and summaries.
Run: ``python examples/compare_laws.py [--degrees 360] [--figure laws.svg]``.
"""

from __future__ import annotations

import argparse

import numpy as np

import vtool


def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--preset", default="gnilka-1a")
    parser.add_argument("--laws", default="local,thesis,momentum")
    parser.add_argument("--degrees", type=float, default=300.0, help="cam degrees per run")
    parser.add_argument("--figure", help="also draw the cam contact force of each law (.png, .svg or .pdf)")
    args = parser.parse_args(argv)

    base = vtool.load(args.preset).set(degrees=args.degrees)
    results = {law: base.set({"contact.impact": law}).solve() for law in args.laws.split(",")}
    print(base.title)
    for law, result in results.items():
        summary = result.summary()
        counts = ", ".join(f"{c['clearance']} {c['separations']}s/{c['impacts']}i" for c in summary["clearances"])
        peak = float(np.max(result.contact_force("cam")))
        print(f"{law:>9}: {summary['events']:>3} events ({counts}); peak cam force {peak:.5g} "
              f"{result.spec.unit_system.force}")
    if args.figure:
        from vtool.app.figures import save_figure
        from vtool.chart import Chart, Panel, curve

        force = base.spec.unit_system.force
        chart = Chart("cam contact force by impact law", "cam angle (deg)",
                      (Panel(tuple(curve(law, r.cam_angle, r.contact_force("cam")) for law, r in results.items()),
                             f"cam contact force ({force})"),), base.title)
        save_figure([chart], args.figure)
        print(f"wrote {args.figure}")
    return results


if __name__ == "__main__":
    main()
