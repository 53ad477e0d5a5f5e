"""The ``aftmesh`` command (run in-process through ``main``) and the example domains."""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import shapely

import aftmesh
from aftmesh import examples
from aftmesh.checks import check_mesh
from aftmesh.cli import main
from aftmesh.io import read_poly

triangle = pytest.importorskip("triangle")
TRIANGLE_DATA = Path(triangle.__file__).parent / "data"
SQUARE_WITH_HOLE = "POLYGON ((0 0, 4 0, 4 2, 0 2, 0 0), (1 0.5, 1.5 0.5, 1.5 1.5, 1 1.5, 1 0.5))"


@pytest.fixture
def checked_generate(monkeypatch):
    """Make every mesh the command generates go through the invariant checker, with
    the domain's area when it is a shapely domain; return the list of meshes."""
    module = sys.modules["aftmesh.generate"]
    original = module.generate
    made = []

    def generate(domain, *args, **kwargs):
        mesh = original(domain, *args, **kwargs)
        area = None
        if isinstance(domain, shapely.Geometry):
            area = domain.area
        elif isinstance(domain, list) and all(isinstance(d, shapely.Geometry) for d in domain):
            area = sum(d.area for d in domain)
        check_mesh(mesh, domain_area=area)
        made.append(mesh)
        return mesh

    monkeypatch.setattr(module, "generate", generate)
    return made


def _error_line(capsys) -> str:
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    return lines[0]


# ------------------------------------------------------------------ demo


def test_demo_quick_writes_files_and_prints_the_summary(tmp_path, capsys, checked_generate):
    pytest.importorskip("meshio")
    pytest.importorskip("matplotlib")
    import meshio

    assert main(["demo", "--quick", "--out", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out
    names = sorted(p.name for p in (tmp_path / "out").iterdir())
    assert names == [
        "demo_airfoil.png",
        "demo_airfoil.vtu",
        "demo_inclusion.png",
        "demo_inclusion.vtu",
    ]
    assert len(checked_generate) == 2
    airfoil, inclusion = checked_generate
    assert set(np.unique(inclusion.regions).tolist()) == {0, 1}
    for mesh, stem in ((airfoil, "demo_airfoil"), (inclusion, "demo_inclusion")):
        q = mesh.quality()
        assert f"{mesh.n_triangles} triangles, {mesh.n_points} points" in out
        assert f"min {q['min_angle']:.2f} deg, max {q['max_angle']:.2f} deg" in out
        assert (
            f"mean {q['radius_ratio_mean']:.4f}, min {q['radius_ratio_min']:.4f}, "
            f"{100 * q['fraction_rr_above_0.9']:.1f} % above 0.9"
        ) in out
        assert f"{mesh.info['timing']['total']:.3f} s (boundary" in out
        back = meshio.read(tmp_path / "out" / f"{stem}.vtu")
        np.testing.assert_array_equal(back.cells[0].data, mesh.triangles)
        assert (tmp_path / "out" / f"{stem}.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # the quick demo is small: a few hundred to a few thousand triangles
    assert 200 < airfoil.n_triangles < 3000 and 200 < inclusion.n_triangles < 3000


def test_demo_without_meshio_and_matplotlib(tmp_path, capsys, monkeypatch, checked_generate):
    monkeypatch.setitem(sys.modules, "meshio", None)
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    monkeypatch.chdir(tmp_path)  # the default output directory
    assert main(["demo", "--quick"]) == 0
    out = capsys.readouterr().out
    assert "meshio is not installed" in out and "matplotlib is not installed" in out
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        f"demo_{n}.{e}" for n in ("airfoil", "inclusion") for e in ("poly", "node", "ele")
    )
    airfoil = checked_generate[0]
    d = read_poly(tmp_path / "demo_airfoil.poly")
    np.testing.assert_array_equal(d["vertices"], airfoil.points)
    assert len(d["holes"]) == 1  # the airfoil


# ------------------------------------------------------------------ mesh


def test_mesh_a_poly_file(tmp_path, capsys, checked_generate):
    pytest.importorskip("meshio")
    pytest.importorskip("matplotlib")
    poly = TRIANGLE_DATA / "double_hex.poly"
    status = main(
        [
            "mesh",
            str(poly),
            "--size",
            "0.05",
            "--stats",
            "--out",
            str(tmp_path / "m.vtu"),
            "--png",
            str(tmp_path / "m.png"),
            "--color-by",
            "region",
        ]
    )
    assert status == 0
    (mesh,) = checked_generate
    out = capsys.readouterr().out
    assert out.startswith(f"double_hex.poly: {mesh.n_triangles} triangles")
    assert "radius ratio: mean" in out and "time:" in out
    assert (tmp_path / "m.vtu").stat().st_size > 0 and (tmp_path / "m.png").stat().st_size > 0
    # the two hexagonal holes of the file are holes of the mesh
    holes = read_poly(poly)["holes"]
    q = aftmesh.mesh.triangle_quality(mesh.points, mesh.triangles)
    assert q["edge_lengths"].max() < 0.05 * 1.6
    for x, y in holes:
        v = mesh.points[mesh.triangles] - (x, y)
        w = np.roll(v, -1, axis=1)
        cross = v[:, :, 0] * w[:, :, 1] - v[:, :, 1] * w[:, :, 0]
        assert not (cross >= 0).all(axis=1).any()  # in no (counter-clockwise) triangle


def test_mesh_a_wkt_file_options(tmp_path, capsys, checked_generate):
    wkt = tmp_path / "sq.wkt"
    wkt.write_text(SQUARE_WITH_HOLE)
    status = main(
        [
            "mesh",
            str(wkt),
            "--size",
            "0.2",
            "--order",
            "oldest",
            "--max-triangles",
            "5000",
            "--out",
            str(tmp_path / "sq.ele"),
        ]
    )
    assert status == 0
    (mesh,) = checked_generate
    out = capsys.readouterr().out
    assert "radius ratio" not in out  # no --stats: one line per action
    assert out.splitlines()[-1] == f"wrote {tmp_path / 'sq.ele'}"
    ref = triangle.load(str(tmp_path), "sq")
    np.testing.assert_array_equal(ref["triangles"], mesh.triangles)
    assert abs(mesh.area() - 7.5) < 1e-12


def test_mesh_a_geojson_file(tmp_path, capsys, checked_generate):
    p = tmp_path / "d.geojson"
    p.write_text(
        '{"type": "Feature", "properties": {}, "geometry": {"type": "Polygon", '
        '"coordinates": [[[0, 0], [3, 0], [0, 2], [0, 0]]]}}'
    )
    assert main(["mesh", str(p), "--size", "0.25"]) == 0
    (mesh,) = checked_generate
    assert abs(mesh.area() - 3.0) < 1e-12


def _bad_poly(tmp_path):
    p = tmp_path / "bad.poly"
    p.write_text("3 2 0 0\n1 0 0\n2 1 0\n3 0 1\n3 0\n1 1 2\n2 2 3\n3 3 7\n0\n")
    return p


def _bow_tie(tmp_path):
    p = tmp_path / "bow.wkt"
    p.write_text("POLYGON ((0 0, 1 1, 1 0, 0 1, 0 0))")
    return p


def _square(tmp_path):
    p = tmp_path / "sq.wkt"
    p.write_text(SQUARE_WITH_HOLE)
    return p


@pytest.mark.parametrize(
    "make_args, fragment",
    [
        (lambda t: ["mesh", str(t / "missing.poly")], "missing.poly: No such file"),
        (
            lambda t: ["mesh", str(_square(t).rename(t / "sq.txt"))],
            "must be a .poly, .wkt or .geojson",
        ),
        (lambda t: ["mesh", str(_bad_poly(t))], "bad.poly, line 8: segment endpoint 7"),
        (lambda t: ["mesh", str(_bow_tie(t))], "bow.wkt: the polygon is not a valid polygon"),
        (
            lambda t: ["mesh", str(_square(t)), "--size", "0.1", "--max-triangles", "3"],
            "sq.wkt: max_triangles=3 is below",
        ),
        (lambda t: ["mesh", str(_square(t)), "--out", str(t / "sq.xyz")], "'sq.xyz'"),
        (
            lambda t: ["mesh", str(_square(t)), "--out", str(t / "no" / "dir" / "sq.poly")],
            "No such file or directory",
        ),
    ],
)
def test_bad_input_exits_2_with_one_line(tmp_path, capsys, make_args, fragment):
    assert main(make_args(tmp_path)) == 2
    line = _error_line(capsys)
    assert line.startswith("aftmesh: error: ") and fragment in line, line


@pytest.mark.parametrize(
    "argv, fragment",
    [
        (["mesh", "x.wkt", "--size", "-1"], "--size: must be a finite positive number"),
        (["mesh", "x.wkt", "--size", "abc"], "not a number"),
        (["mesh", "x.wkt", "--order", "random"], "invalid choice: 'random'"),
        (["frobnicate"], "invalid choice"),
        ([], "required: COMMAND"),
    ],
)
def test_usage_errors_exit_2(capsys, argv, fragment):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert err.strip().splitlines()[-1].endswith(fragment) or fragment in err


def test_unusable_outputs_fail_before_meshing(tmp_path, capsys, checked_generate, monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    assert main(["mesh", str(_square(tmp_path)), "--png", str(tmp_path / "x.png")]) == 2
    assert r"pip install aftmesh[plot]" in _error_line(capsys)
    assert main(["mesh", str(_square(tmp_path)), "--out", str(tmp_path / "x.abc")]) == 2
    _error_line(capsys)
    assert checked_generate == []


def test_version_and_help(capsys):
    assert main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"aftmesh {aftmesh.__version__}"
    assert main(["mesh", "--help"]) == 0
    assert "--max-triangles" in capsys.readouterr().out


def test_python_dash_m(tmp_path):
    wkt = _square(tmp_path)
    src = str(Path(aftmesh.__file__).resolve().parents[1])
    env = dict(os.environ, PYTHONPATH=src + os.pathsep + os.environ.get("PYTHONPATH", ""))
    run = subprocess.run(
        [sys.executable, "-m", "aftmesh", "mesh", str(wkt), "--size", "0.5"],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
    )
    assert run.returncode == 0, run.stderr
    assert run.stdout.startswith("sq.wkt: ") and " triangles, " in run.stdout
    bad = subprocess.run(
        [sys.executable, "-m", "aftmesh", "mesh", str(tmp_path / "no.wkt")],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
    )
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1


# ------------------------------------------------------------------ example domains


def test_naca0012_shape():
    xy = examples.naca0012(spacing=0.005)
    n = len(xy)
    assert xy[0].tolist() == [1.0, 0.0] and xy[n // 2].tolist() == [0.0, 0.0]
    # symmetric, 12 % thick near 30 % of the chord, counter-clockwise
    np.testing.assert_array_equal(xy[1 : n // 2, 0], xy[: n // 2 : -1, 0])
    np.testing.assert_array_equal(xy[1 : n // 2, 1], -xy[: n // 2 : -1, 1])
    top = np.argmax(xy[:, 1])
    assert abs(2 * xy[top, 1] - 0.12) < 1e-4 and abs(xy[top, 0] - 0.3) < 0.01
    assert shapely.Polygon(xy).exterior.is_ccw
    steps = np.linalg.norm(np.diff(np.r_[xy, xy[:1]], axis=0), axis=1)
    assert steps.max() < 0.005 * 1.01 and steps.min() > 0.005 * 0.9
    # the thickness formula at x = 0.5: 5 t (0.2969 sqrt(x) - ...)
    x = 0.5
    yt = 0.6 * (0.2969 * x**0.5 - 0.1260 * x - 0.3516 * x**2 + 0.2843 * x**3 - 0.1036 * x**4)
    upper = xy[: n // 2 + 1][::-1]
    assert abs(np.interp(x, upper[:, 0], upper[:, 1]) - yt) < 1e-5


def test_airfoil_channel(checked):
    domain, size = examples.airfoil_channel(alpha=4.0, h_near=0.04, h_far=0.25)
    (hole,) = domain.interiors
    foil = np.asarray(hole.coords)
    # nose up: the leading edge (the left end) is above the trailing edge
    nose, tail = foil[np.argmin(foil[:, 0])], foil[np.argmax(foil[:, 0])]
    pitch = np.degrees(np.arctan2(nose[1] - tail[1], tail[0] - nose[0]))
    assert pitch == pytest.approx(4.0, abs=0.01)
    assert domain.bounds == (-1.5, -1.25, 3.5, 1.25)
    # the size against a brute-force distance, near and far
    rng = np.random.default_rng(3)
    x = rng.uniform(-1.5, 3.5, 2000)
    y = rng.uniform(-1.25, 1.25, 2000)
    d = shapely.distance(shapely.points(x, y), shapely.Polygon(foil))
    np.testing.assert_allclose(size(x, y), np.minimum(0.25, 0.04 + 0.25 * d), rtol=1e-12)
    assert size(np.float64(0.5), 0.0) == 0.04 and size(3.4, 1.2) == 0.25
    assert size(x.reshape(40, 50), y.reshape(40, 50)).shape == (40, 50)
    mesh = checked(aftmesh.generate(domain, size), domain_area=domain.area)
    # finer at the airfoil than far away
    q = aftmesh.mesh.triangle_quality(mesh.points, mesh.triangles)
    centroid = mesh.points[mesh.triangles].mean(axis=1)
    dist = shapely.distance(shapely.points(centroid), shapely.Polygon(foil))
    h = q["edge_lengths"].mean(axis=1)
    assert h[dist < 0.05].mean() < 0.06 and h[dist > 1].mean() > 0.18


def test_inclusion(checked):
    (annulus, core), size = examples.inclusion(h_core=0.1, h_far=0.3)
    assert annulus.area == 5.0 and core.area == 1.0 and annulus.intersection(core).area == 0
    mesh = checked(aftmesh.generate([annulus, core], size), domain_area=6.0)
    area = aftmesh.mesh.triangle_quality(mesh.points, mesh.triangles)["area"]
    assert area[mesh.regions == 1].sum() == pytest.approx(1.0, abs=1e-12)
    assert area[mesh.regions == 0].sum() == pytest.approx(5.0, abs=1e-12)
    # every triangle of region 1 is inside the core
    centroid = mesh.points[mesh.triangles].mean(axis=1)
    assert shapely.contains_xy(core, centroid[mesh.regions == 1]).all()


def test_graded_size_rejects_bad_parameters():
    with pytest.raises(ValueError, match="h_near <= h_far"):
        examples.GradedSize(shapely.Point(0, 0), 0.5, 0.1)
