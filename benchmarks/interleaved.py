"""Two builds of aftmesh timed in one process, their calls interleaved: how much one
change moves the time, on a machine whose speed drifts.

``python -m benchmarks.interleaved OLD NEW CASE [CASE ...]`` loads the package under
``OLD/src/aftmesh`` and the one under ``NEW/src/aftmesh`` (two checkouts or worktrees,
each with its kernel built in place) side by side, and meshes each case (any name of
``benchmarks.instructions``: the fixed-cost strip and its forms, the "small and real"
outlines, the main table's cases) with one, then the other, ``--calls`` times, the
order swapped each round.  It prints the CPU time per call of each build (median and
least), the median of the per-round ratios NEW / OLD, and whether the two builds made
the same mesh.

Runs of one build in separate processes, alternating, move by 10 % and more here
between runs; two calls made a moment apart share the machine's state, so the ratio
of each round's pair holds still to about half a percent (OLD against itself), which
an optimisation of a few percent can be read against.  The packages use relative
imports only and the kernel imports nothing of the package, so each build runs its
own code.  Nothing here is asserted.
"""

from __future__ import annotations

import argparse
import importlib.util
import statistics
import sys
import time
from pathlib import Path

# Rounds per case when --calls is not given: each round is one call of each build.
DEFAULT_CALLS = 40


def load_build(root: Path, name: str):
    """The aftmesh package under root/src/aftmesh, imported as `name`."""
    pkg = root / "src" / "aftmesh"
    if not any(pkg.glob("_kernel*")):
        raise SystemExit(f"{pkg} holds no built kernel (python setup.py build_ext --inplace)")
    spec = importlib.util.spec_from_file_location(
        name, pkg / "__init__.py", submodule_search_locations=[str(pkg)]
    )
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def summary(old: list[float], new: list[float]) -> dict:
    """Medians and least times (ms) of each build, and the median of the rounds'
    ratios new / old.

    >>> s = summary([0.010, 0.012, 0.011], [0.009, 0.012, 0.010])
    >>> s["old_ms"], s["new_ms"], round(s["ratio"], 3)
    (11.0, 10.0, 0.909)
    """
    return {
        "old_ms": statistics.median(old) * 1e3,
        "new_ms": statistics.median(new) * 1e3,
        "old_min_ms": min(old) * 1e3,
        "new_min_ms": min(new) * 1e3,
        "ratio": statistics.median(b / a for a, b in zip(old, new)),
    }


def _same(a, b) -> bool:
    import numpy as np

    return bool(
        np.array_equal(a.points, b.points)
        and np.array_equal(a.triangles, b.triangles)
        and np.array_equal(a.regions, b.regions)
    )


def run_case(old, new, name: str, calls: int) -> dict:
    """Interleaved CPU times of generate for one case: see the top of this file."""
    from .instructions import generate_args

    args, kwargs = generate_args(name)
    same = _same(old.generate(*args, **kwargs), new.generate(*args, **kwargs))
    times: dict = {id(old): [], id(new): []}
    for k in range(calls):
        for build in (old, new) if k % 2 == 0 else (new, old):
            t0 = time.process_time()
            build.generate(*args, **kwargs)
            times[id(build)].append(time.process_time() - t0)
    return {"case": name, "same": same, **summary(times[id(old)], times[id(new)])}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("old", type=Path, help="checkout of the old build (kernel built in place)")
    ap.add_argument("new", type=Path, help="checkout of the new build")
    ap.add_argument("cases", nargs="+")
    ap.add_argument("--calls", type=int, default=DEFAULT_CALLS, help="rounds per case")
    args = ap.parse_args(argv)
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
    old = load_build(args.old.resolve(), "aftmesh_old")
    new = load_build(args.new.resolve(), "aftmesh_new")
    print(f"old: {old.__file__}\nnew: {new.__file__}")
    print(f"{'case':<24}{'old ms':>9}{'new ms':>9}{'old min':>9}{'new min':>9}{'new/old':>9}  same")
    for name in args.cases:
        r = run_case(old, new, name, args.calls)
        print(
            f"{name:<24}{r['old_ms']:>9.2f}{r['new_ms']:>9.2f}{r['old_min_ms']:>9.2f}"
            f"{r['new_min_ms']:>9.2f}{r['ratio']:>9.3f}  {'yes' if r['same'] else 'NO'}"
        )


if __name__ == "__main__":
    main()
