"""The ``aftmesh`` command.

``aftmesh demo [--out DIR] [--quick]``
    Mesh the embedded examples (a NACA 0012 airfoil in a channel with a graded size;
    a two-material inclusion), write each mesh (``.vtu`` with meshio, otherwise
    ``.poly`` and ``.node``/``.ele``) and a picture (with matplotlib), and print counts,
    quality and timings.

``aftmesh mesh INPUT [--size H] [--out FILE] [--png FILE] [--stats] ...``
    Mesh a ``.poly``, ``.wkt`` or ``.geojson`` domain.

Exit status: 0 on success; 2 when the command cannot run as asked (invalid input file,
option or domain, unreadable file, missing optional package), with a one-line message
on stderr; an internal error (a bug) keeps its traceback.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

from . import __version__
from .errors import InvalidInputError, KernelError

if TYPE_CHECKING:
    from .mesh import Mesh

__all__ = ["main"]

_INPUT_READERS = {
    ".poly": "read_poly",
    ".wkt": "read_wkt",
    ".geojson": "read_geojson",
    ".json": "read_geojson",
}


class _UserError(Exception):
    """Ends the command with a one-line message and exit status 2."""


def _have(module: str) -> bool:
    try:
        __import__(module)
    except ImportError:
        return False
    return True


def _summary(mesh: Mesh, seconds: float | None = None) -> list[str]:
    """The lines the demo and ``mesh --stats`` print about a mesh."""
    q = mesh.quality()
    lines = [
        f"  mesh:         {mesh.n_triangles} triangles, {mesh.n_points} points, "
        f"{len(mesh.segments)} segments",
        f"  angles:       min {q['min_angle']:.2f} deg, max {q['max_angle']:.2f} deg",
        f"  radius ratio: mean {q['radius_ratio_mean']:.4f}, min {q['radius_ratio_min']:.4f}, "
        f"{100 * q['fraction_rr_above_0.9']:.1f} % above 0.9",
    ]
    timing = mesh.info.get("timing", {})
    if timing:
        parts = ", ".join(f"{k} {v:.3f}" for k, v in timing.items() if k != "total")
        total = timing.get("total", seconds)
        lines.append(f"  time:         {total:.3f} s ({parts})")
    elif seconds is not None:
        lines.append(f"  time:         {seconds:.3f} s")
    return lines


def _write_outputs(
    mesh: Mesh,
    stem: Path,
    png: bool,
    have_meshio: bool,
    zoom: tuple[float, float, float, float] | None = None,
    color_by: str = "quality",
) -> list[Path]:
    written = []
    if have_meshio:
        mesh.write(stem.with_suffix(".vtu"))
        written.append(stem.with_suffix(".vtu"))
    else:
        mesh.write(stem.with_suffix(".poly"))
        mesh.write(stem.with_suffix(".node"))
        written += [stem.with_suffix(s) for s in (".poly", ".node", ".ele")]
    if png:
        from .plotting import save_png

        save_png(mesh, stem.with_suffix(".png"), zoom=zoom, color_by=color_by)
        written.append(stem.with_suffix(".png"))
    return written


def _demo(args: argparse.Namespace) -> int:
    from . import examples
    from .generate import generate

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    have_meshio = _have("meshio")
    have_mpl = _have("matplotlib")
    print(
        f"aftmesh {__version__} demo{' (--quick: coarser sizes)' if args.quick else ''}, "
        f"writing into {out}"
    )
    if not have_meshio:
        print(
            "  (meshio is not installed: writing .poly and .node/.ele instead of .vtu; "
            "pip install aftmesh[io])"
        )
    if not have_mpl:
        print("  (matplotlib is not installed: no pictures; pip install aftmesh[plot])")
    if args.quick:
        airfoil = examples.airfoil_channel(h_near=0.04, h_far=0.25)
        inclusion = examples.inclusion(h_core=0.1, h_far=0.3)
    else:
        airfoil = examples.airfoil_channel()
        inclusion = examples.inclusion()
    cases = [
        (
            "airfoil",
            "NACA 0012 airfoil at 4 deg in a channel, size graded "
            f"{airfoil[1].h_near:g} -> {airfoil[1].h_far:g} chord",
            airfoil,
            (-0.15, 1.15, -0.3, 0.3),
            "quality",
        ),
        (
            "inclusion",
            "two materials: a 3 x 2 rectangle with a 1 x 1 core, size "
            f"{inclusion[1].h_near:g} in the core -> {inclusion[1].h_far:g}",
            inclusion,
            None,
            "region",
        ),
    ]
    for name, title, (domain, size), zoom, color_by in cases:
        print(f"\n{title}")
        start = time.perf_counter()
        mesh = generate(domain, size)
        for line in _summary(mesh, time.perf_counter() - start):
            print(line)
        written = _write_outputs(
            mesh, out / f"demo_{name}", have_mpl, have_meshio, zoom=zoom, color_by=color_by
        )
        print(f"  wrote:        {', '.join(str(p) for p in written)}")
    return 0


def _read_domain(path: Path) -> Any:
    from . import io

    reader = _INPUT_READERS.get(path.suffix.lower())
    if reader is None:
        raise _UserError(
            f"cannot tell the format of {path}: the input must be a .poly, .wkt or .geojson file"
        )
    return getattr(io, reader)(path)


def _mesh(args: argparse.Namespace) -> int:
    from .generate import generate
    from .io import mesh_format

    path = Path(args.input)
    if args.out:
        mesh_format(args.out)  # an unusable output name fails now, not after meshing
    if args.png and not _have("matplotlib"):
        raise _UserError("--png needs matplotlib: pip install aftmesh[plot]")
    domain = _read_domain(path)
    start = time.perf_counter()
    try:
        mesh = generate(domain, args.size, max_triangles=args.max_triangles, order=args.order)
    except InvalidInputError as exc:
        raise _UserError(f"{path.name}: {exc}") from None
    seconds = time.perf_counter() - start
    q = mesh.quality()
    print(
        f"{path.name}: {mesh.n_triangles} triangles, {mesh.n_points} points, "
        f"min angle {q['min_angle']:.2f} deg ({seconds:.3f} s)"
    )
    if args.stats:
        for line in _summary(mesh, seconds)[1:]:
            print(line)
        if mesh.info.get("cleanup"):
            print(f"  clean-up:     {'; '.join(mesh.info['cleanup'])}")
    if args.out:
        mesh.write(args.out)
        print(f"wrote {args.out}")
    if args.png:
        from .plotting import save_png

        save_png(mesh, args.png, color_by=args.color_by)
        print(f"wrote {args.png}")
    return 0


def _positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not (value > 0 and value < float("inf")):
        raise argparse.ArgumentTypeError(f"must be a finite positive number, got {text!r}")
    return value


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="aftmesh",
        description="2D triangle meshes by the advancing-front technique on a "
        "constrained Delaunay triangulation.",
    )
    parser.add_argument("--version", action="version", version=f"aftmesh {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    demo = sub.add_parser(
        "demo",
        help="mesh the embedded examples, write files, print quality and timing",
        description="Mesh a NACA 0012 airfoil in a channel (graded "
        "size) and a two-material inclusion; write "
        "demo_*.vtu and demo_*.png; print quality and "
        "timing.",
    )
    demo.add_argument(
        "--out",
        default=".",
        metavar="DIR",
        help="directory for the files (default: the current one)",
    )
    demo.add_argument(
        "--quick", action="store_true", help="coarser sizes: a few hundred triangles each"
    )

    mesh = sub.add_parser(
        "mesh",
        help="mesh a .poly, .wkt or .geojson domain",
        description="Mesh the domain in INPUT (Triangle .poly, WKT or GeoJSON).",
    )
    mesh.add_argument("input", metavar="INPUT", help="a .poly, .wkt or .geojson file")
    mesh.add_argument(
        "--size",
        type=_positive_float,
        metavar="H",
        help="target edge length (default: from the input edges)",
    )
    mesh.add_argument(
        "--out", metavar="FILE", help="write the mesh: .vtu, .msh, ... (meshio), .poly, .node/.ele"
    )
    mesh.add_argument("--png", metavar="FILE", help="write a picture (matplotlib)")
    mesh.add_argument(
        "--color-by",
        choices=["quality", "region", "none"],
        default="quality",
        help="fill of the picture's triangles",
    )
    mesh.add_argument("--stats", action="store_true", help="print the quality summary and timings")
    mesh.add_argument("--max-triangles", type=int, metavar="N", help="never more than N triangles")
    mesh.add_argument(
        "--order",
        choices=["shortest", "longest", "oldest"],
        default="shortest",
        help="which front edge to advance next (default: shortest)",
    )
    return parser


def _fail(message: str) -> int:
    print(f"aftmesh: error: {' '.join(str(message).split())}", file=sys.stderr)
    return 2


def main(argv: list[str] | None = None) -> int:
    """Run the ``aftmesh`` command line; return the exit status.

    Parameters
    ----------
    argv : list of str, optional
        The arguments (default: ``sys.argv[1:]``).

    Examples
    --------
    >>> main(["--version"])    # doctest: +ELLIPSIS
    aftmesh ...
    0
    >>> main(["mesh", "no-such-file.wkt"])    # prints the error on stderr
    2
    """
    try:
        args = _parser().parse_args(argv)
    except SystemExit as exc:  # --help, --version, or a usage error (status 2)
        return int(exc.code or 0)
    try:
        return _demo(args) if args.command == "demo" else _mesh(args)
    except _UserError as exc:
        return _fail(str(exc))
    except KernelError:
        print(
            "aftmesh: internal error (a bug in aftmesh, please report it with the input):",
            file=sys.stderr,
        )
        raise
    except InvalidInputError as exc:  # every aftmesh input error (a ValueError)
        return _fail(str(exc))
    except OSError as exc:  # a file that cannot be read or written
        if exc.filename and exc.strerror:
            return _fail(f"{exc.filename}: {exc.strerror}")
        return _fail(str(exc))
    except ModuleNotFoundError as exc:
        if exc.name not in ("meshio", "matplotlib"):
            raise  # a broken installation, not a missing extra
        return _fail(str(exc))
    except KeyboardInterrupt:
        print("aftmesh: interrupted", file=sys.stderr)
        return 130
