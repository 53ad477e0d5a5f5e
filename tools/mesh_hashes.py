"""Hash the meshes ``generate`` makes of the test suite's domains.

A restructuring that must not change behaviour is checked by running this before and
after and comparing: ``python tools/mesh_hashes.py > before.json`` then
``python tools/mesh_hashes.py --compare before.json``.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "tests"))

from domain_cases import TRIANGLE_SAMPLES, shapely_cases, triangle_sample  # noqa: E402

import aftmesh  # noqa: E402


def _digest(mesh) -> str:
    h = hashlib.sha256()
    for name in ("points", "triangles", "regions", "segments", "segment_markers"):
        arr = getattr(mesh, name, None)
        if arr is not None:
            h.update(name.encode())
            h.update(np.ascontiguousarray(arr).tobytes())
    return h.hexdigest()[:16]


def cases():
    for case in shapely_cases():
        yield case.name, case.domain, case.size
    for name in TRIANGLE_SAMPLES:
        case = triangle_sample(name)
        yield "poly-" + name, case.domain, case.size
    from aftmesh import examples

    for name in ("airfoil_channel", "inclusion"):
        dom, size = getattr(examples, name)()
        yield "example-" + name, dom, size


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--compare", help="a JSON file written by an earlier run")
    args = ap.parse_args()
    out = {}
    for name, dom, size in cases():
        try:
            out[name] = _digest(aftmesh.generate(dom, size=size))
        except Exception as exc:  # a refusal is part of the behaviour too
            out[name] = f"{type(exc).__name__}"
    if not args.compare:
        json.dump(out, sys.stdout, indent=1, sort_keys=True)
        print()
        return 0
    with open(args.compare) as f:
        before = json.load(f)
    changed = sorted(k for k in set(before) | set(out) if before.get(k) != out.get(k))
    print(f"{len(out)} meshes, {len(changed)} changed: {', '.join(changed) or '-'}")
    return 1 if changed else 0


if __name__ == "__main__":
    sys.exit(main())
