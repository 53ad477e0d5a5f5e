"""``python -m benchmarks.options [--set OPTIONS ...] [--cases PATTERN ...] [--repeat N]
[--json OUT] [--update-readme]``

What generate's options trade: the real-world group meshed at generate's defaults and
with each variant of ``--set`` (a comma-separated list of ``name=value``, values as
Python literals, e.g. ``--set gradation=1.2 smooth=1,min_angle=None``; by default the
variants of :data:`VARIANTS`).  For each variant it prints the group's averages of the
mean radius ratio, the share above 0.9 and the smallest angle, the sums of the poor
triangles (radius ratio at most 0.9), of the triangles and of the CPU time, and the CPU
time over the defaults'.  Each case's CPU time is the median of ``--repeat`` calls
after a warm-up call, in this process; the variants take turns case by case, so that a
busy machine weighs on all of them alike.

``--json`` keeps the per-case rows; ``--update-readme`` writes the table between
``<!-- options:start -->`` and ``<!-- options:end -->`` in README.md.
"""

from __future__ import annotations

import argparse
import ast
import datetime
import fnmatch
import json
import statistics
import sys
import time
from pathlib import Path

import numpy as np

from .cases import build_case
from .realworld import REALWORLD_CASES

# The variants compared with the defaults when --set is not given: the size field's
# gradation both ways, less smoothing, no minimum-angle pass, input edges kept whole.
VARIANTS = (
    "gradation=1.2",
    "gradation=1.5",
    "smooth=1",
    "smooth=0",
    "min_angle=None",
    "split_boundary=False",
)
# Left out by default: about 0.76 M triangles, several seconds a call, and the README's
# real-world averages leave it out too (a mesher fails on it).
SLOW_CASES = ("rw-poly2tri-debug2",)
README = Path(__file__).resolve().parent.parent / "README.md"
MARKS = ("<!-- options:start -->", "<!-- options:end -->")


def parse_variant(text: str) -> dict:
    """``"a=1.2,b=None"`` -> ``{"a": 1.2, "b": None}`` (values as Python literals)."""
    options = {}
    for item in text.split(","):
        name, sep, value = item.partition("=")
        if not sep or not name.strip():
            raise ValueError(f"--set takes name=value items, got {item!r}")
        options[name.strip()] = ast.literal_eval(value.strip())
    return options


def measure(name: str, options: dict, repeat: int) -> dict:
    """One case at one set of options: quality of the mesh and median CPU time."""
    import aftmesh

    from .measure import quality_stats

    case = build_case(name)
    domain = case.as_triangle_dict()
    mesh = aftmesh.generate(domain, case.size_arg, **options)  # warm-up
    times = []
    for _ in range(repeat):
        t = time.process_time()
        mesh = aftmesh.generate(domain, case.size_arg, **options)
        times.append(time.process_time() - t)
    q = quality_stats(mesh.points, mesh.triangles)
    n = q["triangles"]
    return {
        "triangles": n,
        "rr_mean": q["rr_mean"],
        "share": q["rr_above_0.9"],
        "poor": n - round(q["rr_above_0.9"] * n),
        "min_angle": q["min_angle"],
        "cpu": statistics.median(times),
    }


def summary(rows: dict[str, dict[str, dict]]) -> list[dict]:
    """Per variant (in the order given), the group's averages and sums."""
    base_cpu = sum(r["cpu"] for r in rows["defaults"].values())
    out = []
    for label, per_case in rows.items():
        vals = list(per_case.values())
        cpu = sum(r["cpu"] for r in vals)
        out.append(
            {
                "options": label,
                "rr_mean": float(np.mean([r["rr_mean"] for r in vals])),
                "share": float(np.mean([r["share"] for r in vals])),
                "poor": sum(r["poor"] for r in vals),
                "min_angle": float(np.mean([r["min_angle"] for r in vals])),
                "triangles": sum(r["triangles"] for r in vals),
                "cpu": cpu,
                "cpu_ratio": cpu / base_cpu,
            }
        )
    return out


def table(rows: list[dict], n_cases: int, repeat: int) -> str:
    when = datetime.datetime.now().strftime("%Y-%m-%d %H:%M")
    lines = [
        f"Options on the real-world group ({n_cases} cases, {when}; CPU: median of "
        f"{repeat} calls per case, summed): averages over the cases of the mean radius "
        "ratio, the share above 0.9 and the smallest angle; sums of the poor triangles "
        "(RR <= 0.9), the triangles and the CPU time.",
        "",
        "| options | RR mean | % RR > 0.9 | RR <= 0.9 count | min angle | triangles "
        "| CPU | CPU / defaults |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['options']} | {r['rr_mean']:.4f} | {100 * r['share']:.1f} | {r['poor']} "
            f"| {r['min_angle']:.1f} | {r['triangles']} | {r['cpu']:.3g} s "
            f"| {r['cpu_ratio']:.2f} |"
        )
    return "\n".join(lines) + "\n"


def select(patterns: list[str] | None) -> list[str]:
    names = [n for n in REALWORLD_CASES if n not in SLOW_CASES]
    if not patterns:
        return names
    return [n for n in REALWORLD_CASES if any(fnmatch.fnmatch(n, p) for p in patterns)]


def main(argv=None) -> int:
    p = argparse.ArgumentParser(
        prog="python -m benchmarks.options",
        description="Quality and CPU time of generate's options on the real-world group.",
    )
    p.add_argument("--set", nargs="+", metavar="OPTIONS", help="variants: name=value[,...]")
    p.add_argument("--cases", nargs="+", metavar="PATTERN", help="rw-* names or patterns")
    p.add_argument("--repeat", type=int, default=3, help="timed calls per case (default 3)")
    p.add_argument("--json", type=Path, help="write the per-case rows here")
    p.add_argument("--update-readme", action="store_true", help="write the table in README.md")
    args = p.parse_args(argv)
    if args.repeat < 1:
        p.error("--repeat must be at least 1")
    try:
        variants = {"defaults": {}}
        for text in args.set or VARIANTS:
            variants[text] = parse_variant(text)
    except (ValueError, SyntaxError) as exc:
        p.error(str(exc))
    names = select(args.cases)
    if not names:
        p.error("no real-world case matches --cases")
    rows: dict[str, dict[str, dict]] = {label: {} for label in variants}
    for name in names:
        for label, options in variants.items():
            rows[label][name] = measure(name, options, args.repeat)
        print(f"{name}: done", file=sys.stderr, flush=True)
    text = table(summary(rows), len(names), args.repeat)
    print(text)
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1))
    if args.update_readme:
        from .report import update_readme

        if not update_readme(README, text, *MARKS):
            print(f"{README} has no {MARKS[0]} ... {MARKS[1]} block: not updated")
            return 1
        print(f"updated {README}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
