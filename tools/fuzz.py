#!/usr/bin/env python3
"""Long fuzzing sessions for aftmesh.generate, outside pytest.

    python tools/fuzz.py --minutes 10 --seed 1 --out fuzz-out
    python tools/fuzz.py --replay fuzz-out/fail-....json

The domains, sizes and options come from the hypothesis strategies of
``tests/fuzz_domains.py``; every mesh goes through its oracle (``verify``: check_mesh
with the exact area, boundary kept, CDT against Triangle).  The meshing runs in a
worker process watched by this one, so that a crash (a signal) or a hang (no progress
for ``--timeout`` seconds) is recorded with the input that caused it and the session
goes on with a fresh worker.

Written to ``--out``: ``fail-<class>-<k>.json`` for the first inputs of each failure
class (the case as JSON, exactly: WKB and repr floats; the error and traceback),
``summary.json``, and the worker's scratch files.  Printed: domains meshed, failures
by class, and where their inputs are.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import re
import resource
import signal
import subprocess
import sys
import time
import traceback
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def _src_has_kernel() -> bool:
    """Whether the kernel was built in place in src/ (setup.py build_ext --inplace)."""
    pkg = ROOT / "src" / "aftmesh"
    return any(pkg.glob("_kernel*.so")) or any(pkg.glob("_kernel*.pyd"))


def _paths():
    # the fuzz domains from tests/; aftmesh from src/ if its kernel was built there,
    # otherwise the installed one
    paths = [ROOT / "tests"]
    if _src_has_kernel():
        paths.append(ROOT / "src")
    for p in paths:
        if str(p) not in sys.path:
            sys.path.insert(0, str(p))


# ------------------------------------------------------------------ failure classes
def failure_class(exc: BaseException) -> str:
    """A short key grouping failures by cause: the exception type and the first line
    (first problem) of its message with numbers and coordinates blanked out."""
    msg = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
    msg = msg.split("; ")[0]
    msg = re.sub(r"\[[^\]]*\]", "[...]", msg)
    msg = re.sub(r"\([-0-9., e+]*\)", "(...)", msg)
    msg = re.sub(r"0x[0-9a-fA-F]+", "#", msg)
    msg = re.sub(r"[-+]?\d+(\.\d*)?([eE][-+]?\d+)?", "#", msg)
    return f"{type(exc).__name__}: {msg}"[:140]


def _slug(key: str) -> str:
    head = re.sub(r"[^A-Za-z0-9]+", "-", key)[:40].strip("-")
    return f"{head}-{hashlib.sha1(key.encode()).hexdigest()[:8]}"


def _write_json(path: Path, obj) -> None:
    tmp = path.with_suffix(path.suffix + ".tmp")
    tmp.write_text(json.dumps(obj, indent=1, default=str))
    os.replace(tmp, path)


# ------------------------------------------------------------------------ the worker
class _Stop(Exception):
    pass


def worker(args) -> int:
    """Mesh cases until the deadline; the parent watches ``current.json``."""
    _paths()
    import fuzz_domains as fd
    from hypothesis import HealthCheck, Phase, given, seed, settings

    if args.memory_gb:
        lim = int(args.memory_gb * 2**30)
        resource.setrlimit(resource.RLIMIT_AS, (lim, lim))
    out = Path(args.out)
    stats_path = out / f"worker-{args.worker_id}.json"
    kinds = args.kinds or sorted(fd.GENERATORS)
    counts = Counter()  # per kind: meshed, refused
    failures = Counter()  # per failure class
    examples: dict[str, list] = {}
    seq = 0
    last_stats = time.time()

    def save_stats():
        _write_json(
            stats_path, {"counts": dict(counts), "failures": dict(failures), "examples": examples}
        )

    def one(case):
        nonlocal seq, last_stats
        if time.time() > args.deadline:
            raise _Stop()
        seq += 1
        record = {"seq": seq, "worker": args.worker_id, "case": fd.case_to_json(case)}
        _write_json(out / "current.json", record)
        base = case.kind.split("+")[0].split("/")[0]
        try:
            mesh = fd.run_case(case)
        except (KeyboardInterrupt, _Stop):
            raise
        except BaseException as exc:  # noqa: BLE001 - every failure is counted
            key = failure_class(exc)
            failures[key] += 1
            counts[base + ":failed"] += 1
            files = examples.setdefault(key, [])
            if len(files) < args.keep:
                name = f"fail-{_slug(key)}-w{args.worker_id}-{failures[key]}.json"
                _write_json(
                    out / name,
                    {
                        "class": key,
                        "error": repr(exc)[:2000],
                        "traceback": traceback.format_exc()[-4000:],
                        "case": fd.case_to_json(case),
                    },
                )
                files.append(name)
            save_stats()
        else:
            counts[base + (":meshed" if mesh is not None else ":refused")] += 1
        if time.time() - last_stats > 2.0:
            save_stats()
            last_stats = time.time()

    r = 0
    try:
        while time.time() < args.deadline:
            kind = kinds[r % len(kinds)]
            rich = (r // len(kinds)) % 2 == 1

            @settings(
                max_examples=args.chunk,
                database=None,
                derandomize=False,
                deadline=None,
                phases=[Phase.generate],
                suppress_health_check=list(HealthCheck),
            )
            @seed(args.seed * 1_000_003 + r)
            @given(fd.fuzz_cases(kinds=[kind], rich_options=rich))
            def run(case):
                one(case)

            try:
                run()
            except _Stop:
                break
            r += 1
    finally:
        save_stats()
    return 0


# ------------------------------------------------------------------------ the parent
def supervise(args) -> int:
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    deadline = time.time() + 60.0 * args.minutes
    totals = Counter()
    failures = Counter()
    examples: dict[str, list] = {}
    worker_id = 0
    start = time.time()
    while time.time() < deadline - 1.0:
        worker_id += 1
        cur = out / "current.json"
        if cur.exists():
            cur.unlink()
        cmd = [
            sys.executable,
            str(Path(__file__).resolve()),
            "--worker",
            "--out",
            str(out),
            "--seed",
            str(args.seed * 1000 + worker_id),
            "--worker-id",
            str(worker_id),
            "--deadline",
            repr(deadline),
            "--chunk",
            str(args.chunk),
            "--keep",
            str(args.keep),
            "--memory-gb",
            str(args.memory_gb),
        ]
        if args.kinds:
            cmd += ["--kinds", *args.kinds]
        env = dict(os.environ)
        # the workers import the same aftmesh as this process (see _paths)
        src = [str(ROOT / "src")] if _src_has_kernel() else []
        env["PYTHONPATH"] = os.pathsep.join([*src, str(ROOT / "tests"), env.get("PYTHONPATH", "")])
        proc = subprocess.Popen(
            cmd,
            env=env,
            stdout=subprocess.DEVNULL,
            stderr=open(out / f"worker-{worker_id}.log", "w"),
        )
        last_seq, last_change = None, time.time()
        hung = False
        while proc.poll() is None:
            time.sleep(0.25)
            try:
                seq = json.loads(cur.read_text())["seq"]
            except (OSError, ValueError, KeyError):
                seq = None
            if seq != last_seq:
                last_seq, last_change = seq, time.time()
            elif time.time() - last_change > args.timeout:
                hung = True
                proc.send_signal(signal.SIGKILL)
                proc.wait()
                break
            if time.time() > deadline + args.timeout + 30:
                proc.send_signal(signal.SIGKILL)
                proc.wait()
                break
        wstats = out / f"worker-{worker_id}.json"
        if wstats.exists():
            w = json.loads(wstats.read_text())
            totals.update(w["counts"])
            failures.update(w["failures"])
            for k, files in w["examples"].items():
                examples.setdefault(k, []).extend(files)
        rc = proc.returncode
        if hung or (rc is not None and rc != 0):
            key = (
                f"hang: no progress for {args.timeout:g} s"
                if hung
                else "crash: worker died with " + (f"signal {-rc}" if rc < 0 else f"exit code {rc}")
            )
            failures[key] += 1
            try:
                case = json.loads(cur.read_text())["case"]
            except (OSError, ValueError, KeyError):
                case = None
            base = (case or {}).get("kind", "?").split("+")[0].split("/")[0]
            totals[base + ":failed"] += 1
            files = examples.setdefault(key, [])
            if len(files) < args.keep and case is not None:
                name = f"fail-{_slug(key)}-w{worker_id}.json"
                log = (out / f"worker-{worker_id}.log").read_text()[-4000:]
                _write_json(
                    out / name, {"class": key, "error": key, "traceback": log, "case": case}
                )
                files.append(name)
            print(f"[fuzz] worker {worker_id}: {key}", flush=True)
    elapsed = time.time() - start
    meshed = sum(v for k, v in totals.items() if k.endswith(":meshed"))
    refused = sum(v for k, v in totals.items() if k.endswith(":refused"))
    failed = sum(v for k, v in totals.items() if k.endswith(":failed"))
    summary = {
        "minutes": elapsed / 60,
        "seed": args.seed,
        "domains": meshed + refused + failed,
        "meshed": meshed,
        "refused_ok": refused,
        "failed": failed,
        "by_kind": dict(sorted(totals.items())),
        "failures": dict(failures.most_common()),
        "examples": examples,
        "workers": worker_id,
    }
    _write_json(out / "summary.json", summary)
    print(f"aftmesh fuzz: {elapsed / 60:.1f} min, seed {args.seed}, {worker_id} worker(s)")
    print(
        f"  domains generated: {summary['domains']}  (meshed and verified: {meshed}, "
        f"acceptable refusals: {refused}, failed: {failed})"
    )
    kinds = sorted({k.split(":")[0] for k in totals})
    for k in kinds:
        row = {s: totals.get(f"{k}:{s}", 0) for s in ("meshed", "refused", "failed")}
        print(
            f"    {k:12s} meshed {row['meshed']:6d}  refused {row['refused']:5d}  "
            f"failed {row['failed']:5d}"
        )
    if failures:
        print("  failures by class:")
        for key, n in failures.most_common():
            print(f"    {n:6d}  {key}")
            for f in examples.get(key, [])[:3]:
                print(f"              {out / f}")
    else:
        print("  no failures")
    return 1 if failures else 0


def replay(path: str) -> int:
    """Run one saved case again and print what happens."""
    _paths()
    import fuzz_domains as fd

    d = json.loads(Path(path).read_text())
    case = fd.case_from_json(d.get("case", d))
    print(case)
    print(fd.dumps(case)[:2000])
    t = time.perf_counter()
    try:
        mesh = fd.run_case(case)
    except BaseException:  # noqa: BLE001
        traceback.print_exc()
        return 1
    print(
        "ok:",
        "refused (acceptable)" if mesh is None else mesh,
        f"({time.perf_counter() - t:.2f} s)",
    )
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--minutes", type=float, default=10.0)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default="fuzz-out")
    ap.add_argument(
        "--timeout", type=float, default=120.0, help="seconds without progress that count as a hang"
    )
    ap.add_argument("--kinds", nargs="*", help="generators to use (default: all)")
    ap.add_argument("--chunk", type=int, default=25, help="examples per hypothesis run")
    ap.add_argument("--keep", type=int, default=5, help="inputs kept per failure class")
    ap.add_argument(
        "--memory-gb", type=float, default=8.0, help="address-space limit of the worker (0: none)"
    )
    ap.add_argument("--replay", help="run one saved failure file again")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--worker-id", type=int, default=0, help=argparse.SUPPRESS)
    ap.add_argument("--deadline", type=float, default=0.0, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.replay:
        return replay(args.replay)
    if args.worker:
        return worker(args)
    return supervise(args)


if __name__ == "__main__":
    sys.exit(main())
