"""Jump speed against valve-spring stiffness: where does the follower first leave the cam?

For each spring rate, the cam speed is scanned and bisected (to --tolerance
rev/min) for the first speed at which the follower leaves the cam above
mid-stroke after the first revolution (the ``cam_separations`` metric of
docs/sweep.md). Run: ``python examples/jump_speed.py [--figure jump.png]``.
The defaults are small so that the tests run it in seconds; widen --stiffness,
--scan and --degrees for a study.
"""

from __future__ import annotations

import argparse

import vtool


def main(argv: list[str] | None = None) -> list[tuple[float, float | None]]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--preset", default="gnilka-1a")
    parser.add_argument("--stiffness", default="200,254,320", help="valve-spring rates (lbf/in), comma-separated")
    parser.add_argument("--scan", default="6000:14000:2000", help="speeds to scan, start:stop:step (rev/min)")
    parser.add_argument("--degrees", type=float, default=720.0, help="cam degrees per run (two revolutions)")
    parser.add_argument("--tolerance", type=float, default=100.0, help="bisection tolerance (rev/min)")
    parser.add_argument("--figure", help="also draw jump speed against stiffness (.png, .svg or .pdf)")
    args = parser.parse_args(argv)

    start, stop, step = (float(v) for v in args.scan.split(":"))
    scan = [start + k * step for k in range(int((stop - start) / step) + 1)]
    base = vtool.load(args.preset).set(degrees=args.degrees)
    rows = []
    print(f"{base.title}\n{'stiffness (lbf/in)':>20}  {'jump speed (rev/min)':>20}")
    for stiffness in (float(v) for v in args.stiffness.split(",")):
        search = base.set({"members.valve_spring.stiffness": stiffness}).find_speed(
            "jump-speed", scan, tolerance=args.tolerance)
        rows.append((stiffness, search.speed))
        shown = f"{search.speed:g}" if search.speed is not None else f"- ({search.message})"
        print(f"{stiffness:>20g}  {shown:>20}")
    if args.figure:
        from vtool.app.figures import save_figure
        from vtool.chart import Chart, Panel, curve

        found = [(k, s) for k, s in rows if s is not None]
        chart = Chart("jump speed against valve-spring stiffness", "valve-spring stiffness (lbf/in)",
                      (Panel((curve("jump speed", [k for k, _ in found], [s for _, s in found]),),
                             "jump speed (rev/min)"),), base.title)
        save_figure([chart], args.figure)
        print(f"wrote {args.figure}")
    return rows


if __name__ == "__main__":
    main()
