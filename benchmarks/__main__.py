"""``python -m benchmarks``: see benchmarks/README.md."""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import sys
import time
from pathlib import Path

from . import cases as _cases
from .meshers import DEFAULT_MESHERS, MESHERS

OUT = Path(__file__).resolve().parent / "out"
README = Path(__file__).resolve().parent.parent / "README.md"


def _machine() -> str:
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return f"{cpu}, {os.cpu_count()} cores"


def _load() -> float | None:
    return os.getloadavg()[0] if hasattr(os, "getloadavg") else None


def _meta(quick: bool) -> dict:
    return {
        "date": datetime.datetime.now().strftime("%Y-%m-%d %H:%M"),
        "machine": _machine(),
        "quick": quick,
        "load_start": _load(),
    }


def _versions() -> str:
    from importlib import metadata

    parts = [f"Python {platform.python_version()}"]
    for dist in ("aftmesh", "numpy", "triangle", "gmsh", "scipy"):
        try:
            parts.append(f"{dist} {metadata.version(dist)}")
        except metadata.PackageNotFoundError:
            try:
                mod = __import__(dist)
                parts.append(f"{dist} {getattr(mod, '__version__', '?')}")
            except Exception:
                parts.append(f"{dist} absent")
    return ", ".join(parts)


def parse_args(argv):
    p = argparse.ArgumentParser(
        prog="python -m benchmarks", description="aftmesh against Triangle and Gmsh."
    )
    p.add_argument(
        "--quick", action="store_true", help="fewer cases and repetitions (under a minute)"
    )
    p.add_argument(
        "--cases",
        nargs="+",
        metavar="CASE",
        help="case names or fnmatch patterns (e.g. 'square-*'); any square-<h> or holes-<h> works",
    )
    p.add_argument(
        "--meshers",
        nargs="+",
        metavar="MESHER",
        choices=list(MESHERS),
        help=f"subset of: {', '.join(MESHERS)}",
    )
    p.add_argument("--repeat", type=int, default=5, help="timed runs per measurement (default 5)")
    p.add_argument("--scaling", action="store_true", help="run the scaling study")
    p.add_argument("--cdt", action="store_true", help="run the Delaunay/CDT comparison")
    p.add_argument("--all", action="store_true", help="meshing cases, --cdt and --scaling")
    p.add_argument(
        "--parallel",
        action="store_true",
        help="generate_many and partitions=2 against serial runs, on threads and "
        "a 2-worker Dask LocalCluster (needs distributed)",
    )
    p.add_argument(
        "--overhead",
        action="store_true",
        help="the fixed cost of one generate call on a 100-vertex polygon (see "
        "python -m benchmarks.overhead for its options and the small-and-real group)",
    )
    p.add_argument(
        "--gmsh-limit",
        type=float,
        default=None,
        help="skip Gmsh on cases where aftmesh made more triangles than this "
        "(default 3e4 with --quick, 1e6 otherwise)",
    )
    p.add_argument(
        "--update-readme",
        action="store_true",
        help="write the summary between <!-- bench:start --> and <!-- bench:end --> in README.md",
    )
    p.add_argument(
        "--report-only",
        action="store_true",
        help="run nothing: rebuild results.md (and the README block) from out/results.json",
    )
    p.add_argument(
        "--realworld",
        action="store_true",
        help="the real-world group only: a compact quality table (see realworld.py)",
    )
    p.add_argument("--list", action="store_true", help="list cases and meshers and exit")
    p.add_argument("--out", type=Path, default=OUT, help="output folder (default benchmarks/out)")
    return p.parse_args(argv)


def main(argv=None) -> int:
    from .runner import SetupError

    try:
        return _main(sys.argv[1:] if argv is None else argv)
    except SetupError as exc:  # no aftmesh for the workers: say so once and stop
        print(f"python -m benchmarks: {exc}", file=sys.stderr)
        return 2


def _main(argv) -> int:
    args = parse_args(argv)
    if args.list:
        print("cases:  ", " ".join(_cases.case_names()))
        print("quick:  ", " ".join(_cases.QUICK_CASES))
        from .realworld import REALWORLD_CASES

        print("realworld:", " ".join(REALWORLD_CASES))
        for k, (_label, desc) in MESHERS.items():
            print(f"mesher:  {k:14s} {desc}")
        return 0
    if args.overhead:
        from . import overhead

        overhead.run_overhead(overhead.OVERHEAD_CALLS)
        return 0
    if args.parallel:
        from . import runner

        runner.import_located()  # before parallel imports aftmesh
        from . import parallel

        return parallel.main(args.quick, args.out)
    from . import plots, report, runner

    out: Path = args.out
    out.mkdir(parents=True, exist_ok=True)
    if args.realworld:
        from .realworld import run_group

        return run_group(args, out)
    store = out / "results.json"
    results = {}
    if store.exists():
        try:
            results = json.loads(store.read_text())
        except json.JSONDecodeError:
            results = {}

    if not args.report_only:
        print(f"aftmesh: {runner.locate_aftmesh()}")
        results["meta"] = {"versions": _versions()}
        run_mesh = args.all or args.cases or not (args.scaling or args.cdt)
        t_all = time.perf_counter()
        if run_mesh:
            names = _cases.select_cases(args.cases, args.quick)
            meshers = args.meshers or DEFAULT_MESHERS
            limit = args.gmsh_limit if args.gmsh_limit is not None else (3e4 if args.quick else 1e6)
            print(f"meshing: {len(names)} cases x {len(meshers)} meshers")
            meta = _meta(args.quick)
            sec = runner.run_mesh_suite(
                names, meshers, quick=args.quick, repeat=args.repeat, gmsh_limit=limit
            )
            sec["meta"] = {**meta, "load_end": _load()}
            results["mesh"] = sec
        if args.cdt or args.all:
            print("CDT:")
            meta = _meta(args.quick)
            sec = runner.run_cdt_suite(quick=args.quick, repeat=args.repeat)
            sec["meta"] = {**meta, "load_end": _load()}
            results["cdt"] = sec
        if args.scaling or args.all:
            print("scaling:")
            meta = _meta(args.quick)
            sec = runner.run_scaling(quick=args.quick, repeat=args.repeat)
            sec["meta"] = {**meta, "load_end": _load()}
            results["scaling"] = sec
        print(f"(measured in {time.perf_counter() - t_all:.1f} s)")
        store.write_text(json.dumps(results, indent=1))

    if not any(k in results for k in ("mesh", "cdt", "scaling")):
        print("no results yet: run python -m benchmarks first")
        return 1
    text = report.full_report(results)
    (out / "results.md").write_text(text)
    pngs = []
    try:
        if "mesh" in results:
            pngs += plots.mesh_histograms(results["mesh"], out)
        if "scaling" in results:
            pngs += plots.scaling_plots(results["scaling"], out)
    except ImportError as exc:
        print(f"(no figures: {exc})")
    print()
    print(text)
    print(
        f"written: {out / 'results.md'}, {out / 'results.json'}"
        + (f", {len(pngs)} PNGs" if pngs else "")
    )
    if args.update_readme:
        if report.update_readme(README, report.summary(results)):
            print(f"updated the benchmark block of {README}")
        else:
            print(
                f"{README} has no '{report.START}' ... '{report.END}' block: README left unchanged"
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
