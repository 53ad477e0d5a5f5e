"""Instructions per ``aftmesh.generate`` call, total and per kernel stage, counted by
valgrind's callgrind: a measure that does not move with the machine's load.

``python -m benchmarks.instructions [CASE ...]`` meshes each case (the fixed-cost
strip ``strip-100``, its other forms ``strip-100/none`` (no size), ``strip-100/x3``
(three copies as one multipolygon), ``strip-100/dict-hole`` (a Triangle dict with
a hole point), ``strip-100/whole`` (its input edges kept whole),
``strip-100/callable`` (a size callable), ``strip-100/regions`` (cut in two
regions) and ``strip-100/line`` (a constraint line along it), and the "small
and real" outlines of ``benchmarks.overhead``, by name, or any case of the main
table, ``square-<h>`` for any h among them, given as that table gives it) in a child
process under callgrind, twice: once with ``--calls`` counted calls
after one warm-up call, once with the warm-up call alone.  The difference over the
number of calls is one call's cost, imports and warm-up left out; each stage is the
same difference of the inclusive count of the kernel function that runs it.  The
last column is the number of Lawson flips per point inserted into a Delaunay
triangulation (boundary CDT, background field and the front's new points together),
from callgrind's call counts: the cost that grows with the unmeshed region's width
(benchmarks/README.md, "Scaling").

On a shared machine wall and CPU times of the same build move by tens of percent
between runs, more than most single optimisations change them; an instruction count
is the same from run to run, so two builds can be compared one after the other.  It
is not time (a division counts as one instruction, a cache miss as none), so a claim
about speed still needs the timed benchmarks (``benchmarks.overhead``).  ``--json``
keeps the counts; ``--compare OLD.json`` prints each count over the old one.

Needs valgrind (``apt install valgrind``); nothing here is asserted.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from . import runner

# Cases counted when none is named: the fixed-cost strip, a small outline, a large one.
DEFAULT_CASES = ("strip-100", "poly2tri-tank", "earcut-rain")
# Counted calls per case after the warm-up call (callgrind runs ~50x slower than
# native, and the count is exact, so a few calls are enough).
DEFAULT_CALLS = 3
# The kernel functions reported, by stage: the compiled common case and the Python
# stages both reach them.  Their C names are the Cython module's prefix and the name.
# Stages may nest: "insert" (Delaunay point insertion) counts the background field's
# own insertions as well as the boundary CDT's; "kernel" is the compiled common case
# (0 where the Python stages run instead); "refine" is the whole minimum-angle pass
# with its settling rounds (refine.pxi's refine_settled, the entry of both paths: the
# refine_mesh it may end with is only the pass's second run).
STAGES = (
    ("kernel", "generate_common"),
    ("bgfield", "background_field"),
    ("discr", "_discretize_on"),
    ("insert", "insert_points"),
    ("front", "basic_aft_loop"),
    ("smooth", "smooth"),
    ("refine", "refine_settled"),
)
# A function line of callgrind_annotate --inclusive=yes: the count, then the file and
# the C name (after "kernel_", optionally a Cython def wrapper's number).
_LINE = re.compile(r"^\s*([\d,]+)\s+\([^)]*\)\s+\S*?:__pyx_(?:f|pw)_7aftmesh_7_kernel_(\d*)(\w+)")
_TOTAL = re.compile(r"^\s*([\d,]+)\s.*PROGRAM TOTALS")
# Lines of callgrind_annotate --tree=caller: a caller of the function below, with its
# call count, and the function itself (marked "*").
_KERNEL_FN = r"\S*?:__pyx_f_7aftmesh_7_kernel_(\w+?)(?:\.\S+)?\s"
_CALLER = re.compile(r"^\s*[\d,]+\s.*<\s+" + _KERNEL_FN + r"+\(([\d,]+)x\)")
_CALLEE = re.compile(r"^\s*[\d,]+\s.*\*\s+" + _KERNEL_FN)
# Calls counted, as (caller, callee): the flips of point insertion, and the two
# routines that insert a point (one front point each, one bulk point each).
CALLS = (
    ("lawson_after_insert", "flip"),
    ("basic_aft_loop", "update_internal"),
    ("insert_points", "lawson_after_insert"),
)


def _call_key(caller: str, callee: str) -> str:
    # the key of a CALLS count in per_call's result (and its --json file)
    return f"{caller}>{callee}"


_CHILD = """
import sys
sys.path.insert(0, {root!r})
from benchmarks.instructions import generate_args
import aftmesh
name, calls = {name!r}, {calls}
args, kwargs = generate_args(name)
mesh = aftmesh.generate(*args, **kwargs)
for _ in range(calls):
    aftmesh.generate(*args, **kwargs)
print(len(mesh.triangles))
"""


def case_names() -> list[str]:
    """The named outlines and the strip's other forms (generate_args also takes the
    cases of benchmarks.cases)."""
    from .overhead import overhead_forms, overhead_outline, real_outlines

    return [c.name for c in [overhead_outline()] + real_outlines()] + list(overhead_forms())


def generate_args(name: str) -> tuple[tuple, dict]:
    """generate's arguments for a case: a named outline (polygon and size), or any case
    of ``benchmarks.cases`` (``square-<h>`` for any h, ``naca0012``, ...) given as the
    main table's ``aft`` gives it.  KeyError or ValueError for an unknown name."""
    from .overhead import overhead_forms, overhead_outline, real_outlines

    outline = next((c for c in [overhead_outline()] + real_outlines() if c.name == name), None)
    if outline is not None:
        return (outline.polygon, outline.size), {}
    forms = overhead_forms()
    if name in forms:
        return forms[name]
    from .cases import build_case

    case = build_case(name)
    return (case.as_triangle_dict(), case.size_arg), {"split_boundary": False}


def _unknown(names: list[str]) -> list[str]:
    from .cases import build_case

    bad = []
    for name in sorted(set(names) - set(case_names())):
        try:
            build_case(name)
        except (KeyError, ValueError):
            bad.append(name)
    return bad


def parse_calls(text: str) -> dict[str, int]:
    """The CALLS counts, keyed "caller>callee", from ``callgrind_annotate
    --tree=caller`` output (a pair that did not occur is absent).

    >>> out = '''
    ...   9,000 (9.0%)  <  x.c:__pyx_f_7aftmesh_7_kernel_lawson_after_insert (1,200x) [k.so]
    ...     100 (0.1%)  <  x.c:__pyx_f_7aftmesh_7_kernel_legalize_meshed (7x) [k.so]
    ...   9,100 (9.1%)  *  x.c:__pyx_f_7aftmesh_7_kernel_flip [k.so]
    ...
    ...     500 (0.5%)  <  x.c:__pyx_f_7aftmesh_7_kernel_basic_aft_loop (40x) [k.so]
    ...     500 (0.5%)  *  x.c:__pyx_f_7aftmesh_7_kernel_update_internal.isra.0 [k.so]'''
    >>> sorted(parse_calls(out).items())
    [('basic_aft_loop>update_internal', 40), ('lawson_after_insert>flip', 1200)]
    """
    wanted = {_call_key(a, b) for a, b in CALLS}
    counts: dict[str, int] = {}
    callers: list[tuple[str, int]] = []
    for line in text.splitlines():
        m = _CALLER.match(line)
        if m:
            callers.append((m.group(1), int(m.group(2).replace(",", ""))))
            continue
        m = _CALLEE.match(line)
        if m:
            for caller, n in callers:
                key = _call_key(caller, m.group(1))
                if key in wanted:
                    counts[key] = counts.get(key, 0) + n
        callers = []
    return counts


def parse_annotate(text: str) -> dict[str, int]:
    """The program total (key "total") and the inclusive count of each STAGES function
    from ``callgrind_annotate --inclusive=yes`` output (a function that did not run
    is absent, and counts 0).

    >>> out = '''10,000 (100.0%)  PROGRAM TOTALS
    ...  4,000 (40.00%)  build/x.c:__pyx_f_7aftmesh_7_kernel_smooth [x.so]
    ...  7,500 (75.00%)  build/x.c:__pyx_pw_7aftmesh_7_kernel_59generate_common [x.so]'''
    >>> sorted(parse_annotate(out).items())
    [('generate_common', 7500), ('smooth', 4000), ('total', 10000)]
    """
    wanted = {fn for _, fn in STAGES}
    counts: dict[str, int] = {}
    for line in text.splitlines():
        m = _TOTAL.match(line)
        if m:
            counts["total"] = int(m.group(1).replace(",", ""))
            continue
        m = _LINE.match(line)
        if m and m.group(3) in wanted:
            # a function called recursively or from two places is listed once per
            # context; the largest is the outermost, which includes the others
            n = int(m.group(1).replace(",", ""))
            counts[m.group(3)] = max(counts.get(m.group(3), 0), n)
    return counts


def _annotate(out: Path, *options: str) -> str:
    return subprocess.run(
        ["callgrind_annotate", *options, "--threshold=100", str(out)],
        capture_output=True,
        text=True,
        check=True,
    ).stdout


def _count(name: str, calls: int) -> tuple[dict[str, int], int]:
    """One callgrind run of the child: (its counts, the triangles of the mesh)."""
    env = runner.worker_env()  # the aftmesh the benchmark workers import
    env.update(OMP_NUM_THREADS="1", PYTHONHASHSEED="0")
    child = _CHILD.format(root=str(runner.ROOT), name=name, calls=calls)
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "callgrind.out"
        run = subprocess.run(
            ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}"]
            + [sys.executable, "-c", child],
            cwd=runner.ROOT,
            env=env,
            capture_output=True,
            text=True,
        )
        if run.returncode != 0 or not out.exists():
            tail = (run.stderr.strip().splitlines() or ["no output"])[-1]
            raise RuntimeError(f"{name}: the counted run failed: {tail}")
        counts = parse_annotate(_annotate(out, "--inclusive=yes"))
        counts.update(parse_calls(_annotate(out, "--tree=caller")))
    return counts, int(run.stdout.split()[-1])


def per_call(name: str, calls: int) -> dict:
    """One generate call's instructions on the case, total and per stage."""
    many, triangles = _count(name, calls)
    once, _ = _count(name, 0)
    keys = ["total"] + [fn for _, fn in STAGES] + [_call_key(a, b) for a, b in CALLS]
    return {
        "triangles": triangles,
        "calls": calls,
        **{k: (many.get(k, 0) - once.get(k, 0)) / calls for k in keys},
    }


def flips_per_point(r: dict) -> float:
    """Lawson flips per inserted point, from per_call's counts (nan: none inserted)."""
    flips, front, bulk = (r.get(_call_key(a, b), 0) for a, b in CALLS)
    points = front + bulk
    return flips / points if points else float("nan")


def _row(name: str, r: dict, old: dict | None) -> str:
    def cell(k: str) -> str:
        text = f"{r[k] / 1e6:8.3f}"
        if old and old.get(k):
            text += f" ({r[k] / old[k]:.3f})"
        return text

    per_tri = r["total"] / max(r["triangles"], 1)
    return (
        f"{name:<22}{r['triangles']:>8}{per_tri:>9.0f}  "
        + "  ".join(cell(k) for k in ["total"] + [fn for _, fn in STAGES])
        + f"  {flips_per_point(r):>10.2f}"
    )


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.instructions", description=__doc__)
    parser.add_argument("cases", nargs="*", help=f"case names (default: {' '.join(DEFAULT_CASES)})")
    parser.add_argument("--calls", type=int, default=DEFAULT_CALLS, help="counted calls per case")
    parser.add_argument("--json", type=Path, help="write the counts here")
    parser.add_argument("--compare", type=Path, help="counts of an earlier run (--json)")
    parser.add_argument("--list", action="store_true", help="print the case names")
    args = parser.parse_args(argv)
    if args.list:
        print(" ".join(case_names()))
        return 0
    if shutil.which("valgrind") is None or shutil.which("callgrind_annotate") is None:
        print("valgrind (with callgrind_annotate) is not installed: apt install valgrind")
        return 2
    names = args.cases or list(DEFAULT_CASES)
    unknown = _unknown(names)
    if unknown:
        print(f"unknown cases: {', '.join(unknown)} (see --list)")
        return 2
    old = json.loads(args.compare.read_text()) if args.compare else {}
    print(f"aftmesh: {runner.locate_aftmesh()}")
    print("millions of instructions per generate call (over the old count with --compare)")
    heads = ["total"] + [label for label, _ in STAGES]
    print(
        f"{'case':<22}{'tri':>8}{'per tri':>9}  "
        + "  ".join(f"{h:>8}" for h in heads)
        + f"  {'flips/pt':>10}"
    )
    results = {}
    for name in names:
        results[name] = per_call(name, args.calls)
        print(_row(name, results[name], old.get(name)), flush=True)
    if args.json:
        args.json.write_text(json.dumps(results, indent=1))
    return 0


if __name__ == "__main__":
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    sys.exit(main())
