"""Spring preload study: how much preload keeps the follower on the cam at a given speed?

Sweeps the valve spring's preload (``initial.spring_preload``, lbf) at one cam
speed and prints, per preload, the spring force left over the nose
(``spring_margin``), the separation episodes and the peak cam force after the
first revolution, from the sweep's arrays (a pandas DataFrame too, when pandas
is installed). Run: ``python examples/spring_preload.py [--rpm 10000]``.
"""

from __future__ import annotations

import argparse

import vtool


def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--preset", default="gnilka-1a")
    parser.add_argument("--rpm", type=float, default=10000.0, help="cam speed (rev/min)")
    parser.add_argument("--preloads", default="100,145,200", help="spring preloads (lbf), comma-separated")
    parser.add_argument("--degrees", type=float, default=540.0, help="cam degrees per run")
    args = parser.parse_args(argv)

    model = vtool.load(args.preset).set(rpm=args.rpm, degrees=args.degrees)
    study = model.sweep({"initial.spring_preload": [float(v) for v in args.preloads.split(",")]})
    columns = study.arrays()
    shown = ["initial.spring_preload (lbf)", "spring_margin (lbf)", "cam_separations", "peak_F1 (lbf)"]
    print(f"{model.title}\n" + "  ".join(f"{name:>28}" for name in shown))
    for row in zip(*(columns[name] for name in shown), strict=True):
        print("  ".join(f"{value:>28.6g}" for value in row))
    return columns


if __name__ == "__main__":
    main()
