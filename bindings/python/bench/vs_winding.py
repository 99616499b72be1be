"""obbtree.winding_number against libigl's fast winding number: the same meshes and points,
all cores each unless limited, errors measured against the exact sum.

    python bench/vs_winding.py                 # the bundled cow, and ../shared/meshes
    python bench/vs_winding.py --points 1000000 --no-proven   # the proven column takes minutes

Points are uniform in the mesh's bounding box. libigl (`igl.fast_winding_number`, Barill
et al.'s method at its defaults, expansion order 2 and β = 2; its tree built inside the
call) against obbtree at β = 2 (`obbtree.winding_number`, the default), β = 2.25 (about
libigl's error: obbtree's cluster radius is the exact reach of the corners), β = 3, and
proven within 1e-2 (`tolerance=0.01`); the f64 tree is built beforehand. The error of each is its largest difference from the exact sum (obbtree's
`tolerance=0`) over the first --check points. Times are medians of --repeat runs.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

import obbtree
from common import median_seconds, mesh_of, meshes


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--points", type=int, default=100_000)
    parser.add_argument("--check", type=int, default=2_000)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--no-proven", action="store_true",
                        help="skip the proven column, which takes minutes at 10^6 points")
    args = parser.parse_args()
    import igl

    rng = np.random.default_rng(args.seed)
    ours = {
        "β 2": {},
        "β 2.25": {"beta": 2.25},
        "β 3": {"beta": 3.0},
        "proven 1e-2": {"tolerance": 1e-2},
    }
    if args.no_proven:
        del ours["proven 1e-2"]
    ratios = {name: [] for name in ours}
    print("| mesh | triangles | libigl s | libigl error | " + " | ".join(
        f"{name} s | error | / libigl" for name in ours) + " |")
    print("|---|---:|---:|---:|" + "---:|---:|---:|" * len(ours))
    for name, path in meshes():
        tree = obbtree.build(str(path), precision="f64")
        v, f = mesh_of(tree)
        lo, hi = v.min(0), v.max(0)
        points = lo + (hi - lo) * rng.random((args.points, 3))
        check = points[: args.check]
        exact = obbtree.winding_number(tree, np.eye(4), check, tolerance=0)
        theirs, w = median_seconds(lambda: igl.fast_winding_number(v, f, points), args.repeat)
        row = f"| {name} | {len(f)} | {theirs:.3f} | {np.abs(w[: args.check] - exact).max():.1e} |"
        for label, options in ours.items():
            seconds, w = median_seconds(
                lambda: obbtree.winding_number(tree, np.eye(4), points, **options), args.repeat)
            error = np.abs(w[: args.check] - exact).max()
            ratios[label].append(seconds / theirs)
            row += f" {seconds:.3f} | {error:.1e} | {seconds / theirs:.2f} |"
        print(row, flush=True)
    for label, r in ratios.items():
        g = float(np.exp(np.mean(np.log(r))))
        print(f"\nobbtree {label} / libigl: geomean {g:.2f}, worst {max(r):.2f} over {len(r)} meshes")
    return 0


if __name__ == "__main__":
    sys.exit(main())
