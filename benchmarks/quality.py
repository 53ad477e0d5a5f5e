"""``python -m benchmarks.quality CASE [CASE ...] [--threshold 0.9] [--png out.png]``

Labels each triangle of aftmesh's mesh of a benchmark case whose radius ratio is below
the threshold by where it came from (:func:`aftmesh.diagnose.diagnose`: smoothing,
boundary, size transition, front collision, other), prints the counts per class and
draws the bad triangles coloured by class.  CASE is any benchmark case name (see
``python -m benchmarks --list``), including the real-world group's ``rw-*``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from . import runner
from .cases import build_case

COLOURS = {
    "smoothing": "tab:purple",
    "boundary": "tab:blue",
    "size": "tab:orange",
    "collision": "tab:red",
    "other": "tab:gray",
}
OUT = Path(__file__).resolve().parent / "out"


def diagnose_case(name: str, threshold: float, split: bool = False):
    from aftmesh.diagnose import diagnose

    case = build_case(name)
    return diagnose(
        case.as_triangle_dict(), case.size_arg, threshold=threshold, split_boundary=split
    )


def draw(diag, title: str, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import PolyCollection
    from matplotlib.patches import Patch

    m = diag.mesh
    fig, ax = plt.subplots(figsize=(10, 8))
    ax.triplot(m.points[:, 0], m.points[:, 1], m.triangles, lw=0.1, color="0.75")
    seg = m.points[m.segments]
    ax.plot(seg[:, :, 0].T, seg[:, :, 1].T, lw=0.6, color="k")
    handles = []
    for c, colour in COLOURS.items():
        sel = diag.bad[diag.labels == c]
        if len(sel):
            ax.add_collection(
                PolyCollection(
                    m.points[m.triangles[sel]], facecolor=colour, edgecolor=colour, lw=0.3
                )
            )
            handles.append(Patch(color=colour, label=f"{c} ({len(sel)})"))
    ax.set_aspect("equal")
    ax.set_title(title)
    ax.legend(handles=handles, loc="upper right", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=150)
    plt.close(fig)


def main(argv=None) -> int:
    doc = (__doc__ or "").split("\n\n")
    p = argparse.ArgumentParser(prog="python -m benchmarks.quality", description=doc[1])
    p.add_argument("cases", nargs="+", metavar="CASE")
    p.add_argument(
        "--threshold",
        type=float,
        default=0.9,
        help="radius ratio below which a triangle is bad (default 0.9)",
    )
    p.add_argument(
        "--png",
        type=Path,
        help="picture path (one case), default benchmarks/out/quality_<case>.png",
    )
    p.add_argument(
        "--split",
        action="store_true",
        help="mesh as generate's default does, input segments split (the aft-split "
        "mesher); without it they are kept whole (aft)",
    )
    args = p.parse_args(sys.argv[1:] if argv is None else argv)
    print(f"aftmesh: {runner.locate_aftmesh()}")
    OUT.mkdir(parents=True, exist_ok=True)
    total: dict[str, int] = {}
    for name in args.cases:
        diag = diagnose_case(name, args.threshold, args.split)
        print(f"{name}:")
        print(diag.summary())
        for c, k in diag.counts.items():
            total[c] = total.get(c, 0) + k
        mode = "-split" if args.split else ""
        path = args.png if args.png and len(args.cases) == 1 else OUT / f"quality_{name}{mode}.png"
        draw(diag, f"{name}{mode}: RR < {args.threshold:g} by cause", path)
        print(f"  picture: {path}")
    if len(args.cases) > 1:
        n = max(sum(total.values()), 1)
        print("all cases: " + ", ".join(f"{c} {k} ({100 * k / n:.1f} %)" for c, k in total.items()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
