"""File input/output (Triangle's .poly/.node/.ele, meshio formats, WKT, GeoJSON) and
pictures."""

import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

import aftmesh
from aftmesh import InvalidInputError, InvalidOptionError
from aftmesh.checks import check_mesh
from aftmesh.io import mesh_format, read_geojson, read_poly, read_wkt, write_mesh, write_poly

triangle = pytest.importorskip("triangle")
TRIANGLE_DATA = Path(triangle.__file__).parent / "data"
SAMPLE_POLYS = sorted(p.stem for p in TRIANGLE_DATA.glob("*.poly"))


def _write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


@pytest.fixture(scope="module")
def two_region_mesh():
    """A mesh with two regions, a hole and an interface (the quick inclusion plus a
    hole in the outer material)."""
    from shapely.geometry import Polygon, box

    outer = Polygon(
        box(0, 0, 3, 2).exterior.coords,
        [box(1, 0.5, 2, 1.5).exterior.coords, box(2.3, 0.8, 2.7, 1.2).exterior.coords],
    )
    core = box(1, 0.5, 2, 1.5)
    mesh = aftmesh.generate([outer, core], size=0.2)
    check_mesh(mesh, domain_area=outer.area + core.area)
    return mesh


# ------------------------------------------------------------------ read_poly: samples


def test_the_sample_files_are_there():
    # the parametrized test below would silently test nothing without them
    assert len(SAMPLE_POLYS) >= 15


@pytest.mark.parametrize("name", SAMPLE_POLYS)
def test_read_poly_matches_triangle_on_its_sample_files(name):
    ours = read_poly(TRIANGLE_DATA / f"{name}.poly")
    ref = triangle.get_data(name)
    np.testing.assert_array_equal(ours["vertices"], ref["vertices"])
    np.testing.assert_array_equal(ours["segments"], ref["segments"])
    assert ours["segments"].dtype == np.int32
    for key in ("segment_markers", "vertex_markers"):
        if key in ref:
            np.testing.assert_array_equal(ours[key], np.ravel(ref[key]))
        else:
            assert key not in ours
    if "vertex_attributes" in ref:
        np.testing.assert_array_equal(ours["vertex_attributes"], ref["vertex_attributes"])
    np.testing.assert_array_equal(ours["holes"], ref.get("holes", np.zeros((0, 2))))
    # regions: the triangle package misreads them (see the test below)
    assert ours["regions"].shape == ((6, 4) if name.startswith("la") else (0, 4))


@pytest.mark.parametrize("name", ["la", "la.1"])
def test_region_lines_as_triangle_reads_them(name):
    # la.poly gives one value per region; Triangle uses it as both attribute and area
    # bound: la.1.poly, which Triangle wrote from la.poly, has it in both columns.
    # (The triangle package's Python reader puts it in the area column only, and
    # misreads la.1.poly's five-field lines.)
    regions = read_poly(TRIANGLE_DATA / f"{name}.poly")["regions"]
    np.testing.assert_array_equal(
        regions,
        [
            [6, -0.2, 0.05, 0.05],
            [25, -0.1, 0.05, 0.05],
            [5, -1, 0.2, 0.2],
            [5, -3, 0.4, 0.4],
            [5, -5, 0.8, 0.8],
            [5, -10, 3, 3],
        ],
    )


def test_sample_file_with_fractional_region_attributes_is_refused():
    # la.poly's regional attributes are 0.05, 0.2, 0.4, 0.8 and 3; Mesh.regions holds
    # integer markers, so aftmesh refuses instead of truncating them
    with pytest.raises(aftmesh.InvalidInputError, match=r"regions\[0\] has marker 0.05"):
        aftmesh.generate(str(TRIANGLE_DATA / "la.poly"))


@pytest.mark.parametrize("name", ["A", "double_hex", "face", "square_circle_hole"])
def test_sample_files_mesh(name, checked):
    mesh = checked(aftmesh.generate(str(TRIANGLE_DATA / f"{name}.poly")))
    d = read_poly(TRIANGLE_DATA / f"{name}.poly")
    if "segment_markers" in d:
        # the mesh's segments carry the markers of the file's segments
        assert set(mesh.segment_markers.tolist()) <= set(d["segment_markers"].tolist())


# ------------------------------------------------------------------ read_poly: format


def test_zero_based_file_with_comments_and_missing_optional_fields(tmp_path):
    p = _write(
        tmp_path / "z.poly",
        """
# a square, vertices numbered from 0
4 2 1 1   # one attribute, one marker
0 0 0 7.5 3
1 1 0       # attribute and marker missing: both read as 0
2 1 1 2.5
3 0 1 1 9

4 1
0 0 1 5
1 1 2
2 2 3 6
3 3 0 7
1
0 0.5 0.5e-1
2
0 0.25 0.75 3 0.01
1 0.75 0.75 4
""",
    )
    d = read_poly(p)
    np.testing.assert_array_equal(d["vertices"], [[0, 0], [1, 0], [1, 1], [0, 1]])
    np.testing.assert_array_equal(d["vertex_attributes"], [[7.5], [0], [2.5], [1]])
    np.testing.assert_array_equal(d["vertex_markers"], [3, 0, 0, 9])
    np.testing.assert_array_equal(d["segments"], [[0, 1], [1, 2], [2, 3], [3, 0]])
    np.testing.assert_array_equal(d["segment_markers"], [5, 0, 6, 7])
    np.testing.assert_array_equal(d["holes"], [[0.5, 0.05]])
    np.testing.assert_array_equal(d["regions"], [[0.25, 0.75, 3, 0.01], [0.75, 0.75, 4, 4]])


def test_file_ending_after_the_segments_has_no_holes(tmp_path):
    p = _write(tmp_path / "t.poly", "3 2\n1 0 0\n2 1 0\n3 0 1\n3\n1 1 2\n2 2 3\n3 3 1\n")
    d = read_poly(p)
    assert d["holes"].shape == (0, 2) and d["regions"].shape == (0, 4)
    assert "segment_markers" not in d and "vertex_markers" not in d


def test_poly_with_zero_vertices_reads_the_node_file(tmp_path, checked):
    _write(tmp_path / "sq.1.node", "4 2 0 0\n1 0 0\n2 2 0\n3 2 1\n4 0 1\n")
    p = _write(tmp_path / "sq.1.poly", "0 2 0 0\n4 0\n1 1 2\n2 2 3\n3 3 4\n4 4 1\n0\n")
    d = read_poly(p)
    np.testing.assert_array_equal(d["vertices"], [[0, 0], [2, 0], [2, 1], [0, 1]])
    np.testing.assert_array_equal(d["segments"], [[0, 1], [1, 2], [2, 3], [3, 0]])
    mesh = checked(aftmesh.generate(p, size=0.3), domain_area=2.0)
    assert mesh.n_triangles > 20


def test_poly_with_zero_vertices_and_no_node_file(tmp_path):
    p = _write(tmp_path / "lonely.poly", "0 2 0 0\n0 0\n0\n")
    with pytest.raises(FileNotFoundError, match="lonely.node"):
        read_poly(p)


def test_missing_file():
    with pytest.raises(FileNotFoundError):
        read_poly("/nonexistent/nothing.poly")


_GOOD_HEAD = "3 2 0 0\n1 0 0\n2 1 0\n3 0 1\n"
_GOOD_SEGS = "3 0\n1 1 2\n2 2 3\n3 3 1\n"


@pytest.mark.parametrize(
    "text, line, fragment",
    [
        ("3 2 0 0\n1 0 0\n2 1 zero\n3 0 1\n" + _GOOD_SEGS + "0\n", 3, "y must be a number"),
        ("3 2 0 0\n1 0 0\n2 1 nan\n3 0 1\n" + _GOOD_SEGS + "0\n", 3, "finite"),
        ("3 3 0 0\n", 1, "dimension must be 2"),
        ("three 2 0 0\n", 1, "number of vertices must be an integer"),
        ("-3 2 0 0\n", 1, "must be >= 0"),
        ("3 2 0 2\n", 1, "boundary markers must be 0 or 1"),
        ("3 2 0 0\n2 0 0\n", 2, "numbered 0 or 1"),
        ("3 2 0 0\n1 0 0\n3 1 0\n", 3, "out of sequence"),
        ("3 2 0 0\n1 0 0\n2 1\n", 3, "needs 3 fields"),
        ("3 2 0 0\n1 0 0 5\n", 2, "at most 3 expected"),
        # four vertex lines for three declared: the fourth is read as the segment header
        ("3 2 0 0\n1 0 0\n2 1 0\n3 0 1\n4 1 1\n" + _GOOD_SEGS, 5, "count declared earlier"),
        (_GOOD_HEAD + "3 0\n1 1 2\n2 2 4\n3 3 1\n0\n", 7, "endpoint 4 is not a vertex"),
        (_GOOD_HEAD + "3 0\n1 1 2\n2 2 2\n3 3 1\n0\n", 7, "to itself"),
        (_GOOD_HEAD + "3 0\n1 1 2\n2 2 x\n3 3 1\n0\n", 7, "integer"),
        (_GOOD_HEAD + _GOOD_SEGS + "1 2\n", 9, "hole count line"),
        (_GOOD_HEAD + _GOOD_SEGS + "1\n1 0.1\n", 10, "a hole line"),
        (_GOOD_HEAD + _GOOD_SEGS + "0\n1\n1 0.1 0.1\n", 11, "a region line"),
        (_GOOD_HEAD + _GOOD_SEGS + "0\n0\n5\n", 11, "unexpected data"),
    ],
)
def test_malformed_poly_names_file_and_line(tmp_path, text, line, fragment):
    p = _write(tmp_path / "bad.poly", text)
    with pytest.raises(InvalidInputError) as info:
        read_poly(p)
    msg = str(info.value)
    assert msg.startswith(f"{p}, line {line}: "), msg
    assert fragment in msg


@pytest.mark.parametrize(
    "text, fragment",
    [
        ("", "the vertex count line"),
        ("# only a comment\n", "the vertex count line"),
        ("3 2 0 0\n1 0 0\n2 1 0\n", "vertex 3 of the 3 declared on line 1"),
        (_GOOD_HEAD, "the segment count line"),
        (_GOOD_HEAD + "3 0\n1 1 2\n", "segment 2 of the 3 declared on line 5"),
        (_GOOD_HEAD + _GOOD_SEGS + "2\n1 0.1 0.1\n", "hole 2 of the 2 declared on line 9"),
    ],
)
def test_truncated_poly_says_what_is_missing(tmp_path, text, fragment):
    p = _write(tmp_path / "short.poly", text)
    with pytest.raises(InvalidInputError, match="the file ends where") as info:
        read_poly(p)
    assert str(p) in str(info.value) and fragment in str(info.value)


def test_malformed_poly_through_generate(tmp_path):
    p = _write(tmp_path / "bad.poly", _GOOD_HEAD + "3 0\n1 1 2\n2 2 4\n3 3 1\n0\n")
    with pytest.raises(InvalidInputError, match=r"bad\.poly, line 7"):
        aftmesh.generate(p)


# ------------------------------------------------------------------ write_poly


def test_write_poly_round_trip(tmp_path):
    rng = np.random.default_rng(7)
    xy = rng.normal(size=(9, 2)) * 10.0 ** rng.integers(-8, 8, size=(9, 1))
    seg = np.array([[0, 1], [1, 2], [2, 8], [8, 0], [3, 4]])
    holes = rng.random((2, 2))
    p = tmp_path / "rt.poly"
    write_poly(
        p,
        xy,
        seg,
        holes=holes,
        regions=[(0.1, 0.2, 3), (0.3, 0.4, 5)],
        segment_markers=[1, -2, 3, 4, 0],
    )
    d = read_poly(p)
    np.testing.assert_array_equal(d["vertices"], xy)  # bit for bit
    np.testing.assert_array_equal(d["segments"], seg)
    np.testing.assert_array_equal(d["segment_markers"], [1, -2, 3, 4, 0])
    np.testing.assert_array_equal(d["holes"], holes)
    # no maximum area given: written as -1, not left for Triangle to copy the attribute
    np.testing.assert_array_equal(d["regions"], [[0.1, 0.2, 3, -1], [0.3, 0.4, 5, -1]])
    assert "1 1 2 1" in p.read_text().splitlines()  # numbered from 1


@given(
    arrays(
        np.float64,
        st.tuples(st.integers(1, 6), st.just(2)),
        elements=st.floats(allow_nan=False, allow_infinity=False),
    )
)
def test_write_poly_keeps_every_double(xy):
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        p = Path(tmp) / "f.poly"
        write_poly(p, xy, None)
        back = read_poly(p)["vertices"]
    assert back.tobytes() == xy.tobytes()  # bit for bit, -0.0 and subnormals too


@pytest.mark.parametrize(
    "kwargs, fragment",
    [
        (dict(vertices=[(0, 0), (1, 0)], segments=[(0, 2)]), "outside 0..1"),
        (dict(vertices=[(0, 0), (1, np.nan)], segments=None), "not finite"),
        (dict(vertices=[(0, 0, 0)], segments=None), "shape"),
        (
            dict(vertices=[(0, 0), (1, 0)], segments=[(0, 1)], segment_markers=[1, 2]),
            "2 entries for 1 segments",
        ),
        (dict(vertices=[(0, 0), (1, 0)], segments=[(0, 0.5)]), "integer"),
        (dict(vertices=[(0, 0), (1, 0)], segments=None, regions=[(0, 0)]), "regions"),
    ],
)
def test_write_poly_rejects_bad_arrays(tmp_path, kwargs, fragment):
    with pytest.raises(InvalidInputError, match=fragment):
        write_poly(tmp_path / "x.poly", **kwargs)
    assert not (tmp_path / "x.poly").exists()


# ------------------------------------------------------------------ write_mesh


def test_mesh_poly_round_trip_keeps_holes_and_regions(tmp_path, two_region_mesh, checked):
    m = two_region_mesh
    p = tmp_path / "m.poly"
    m.write(p)
    d = read_poly(p)
    np.testing.assert_array_equal(d["vertices"], m.points)
    np.testing.assert_array_equal(d["segments"], m.segments)
    np.testing.assert_array_equal(d["segment_markers"], m.segment_markers)
    assert len(d["holes"]) == 1
    # the written file meshes to the same triangulation: same vertices, no new ones,
    # same holes and the same region per triangle
    again = checked(aftmesh.generate(p, greedy=True, split_boundary=False), domain_area=m.area())
    assert again.n_triangles == m.n_triangles

    def per_region(mesh):
        area = aftmesh.mesh.triangle_quality(mesh.points, mesh.triangles)["area"]
        return {int(r): float(area[mesh.regions == r].sum()) for r in np.unique(mesh.regions)}

    assert per_region(again) == pytest.approx(per_region(m))
    assert per_region(m) == pytest.approx({0: 6.0 - 1.0 - 0.16, 1: 1.0})


def test_single_region_mesh_poly_has_no_region_section(tmp_path, checked):
    m = checked(aftmesh.generate([(0, 0), (1, 0), (1, 1), (0, 1)], size=0.5))
    write_mesh(m, tmp_path / "s.poly")
    d = read_poly(tmp_path / "s.poly")
    assert d["regions"].shape == (0, 4) and d["holes"].shape == (0, 2)


@pytest.mark.parametrize("written", ["pair.node", "pair.ele"])
def test_node_ele_pair(tmp_path, two_region_mesh, written):
    m = two_region_mesh
    write_mesh(m, tmp_path / written)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pair.ele", "pair.node"]
    ref = triangle.load(str(tmp_path), "pair")
    np.testing.assert_array_equal(ref["vertices"], m.points)
    np.testing.assert_array_equal(ref["triangles"], m.triangles)
    np.testing.assert_array_equal(ref["triangle_attributes"].ravel(), m.regions)
    on_boundary = np.zeros(m.n_points, dtype=int)
    ti, k = np.nonzero(m.neighbors < 0)
    on_boundary[m.triangles[ti, (k + 1) % 3]] = 1
    np.testing.assert_array_equal(ref["vertex_markers"].ravel(), on_boundary)
    assert 0 < on_boundary.sum() < m.n_points


def test_native_format_by_name(tmp_path, two_region_mesh):
    write_mesh(two_region_mesh, tmp_path / "odd.txt", file_format="triangle")
    assert {p.name for p in tmp_path.iterdir()} == {"odd.node", "odd.ele"}
    write_mesh(two_region_mesh, tmp_path / "odd2.txt", file_format="poly")
    assert read_poly(tmp_path / "odd2.txt")["vertices"].shape == two_region_mesh.points.shape


@pytest.mark.parametrize(
    "name, fmt",
    [("m.vtu", None), ("m.vtk", None), ("m.msh", None), ("m.mesh", None), ("m.data", "vtu")],
)
def test_meshio_round_trip(tmp_path, two_region_mesh, name, fmt):
    meshio = pytest.importorskip("meshio")
    m = two_region_mesh
    m.write(tmp_path / name, file_format=fmt)
    back = meshio.read(tmp_path / name, file_format=fmt)
    np.testing.assert_array_equal(back.points[:, :2], m.points)
    if back.points.shape[1] == 3:
        assert not back.points[:, 2].any()
    # the triangles first, then the segments as line cells
    assert [block.type for block in back.cells] == ["triangle", "line"]
    np.testing.assert_array_equal(back.cells[0].data, m.triangles)
    np.testing.assert_array_equal(back.cells[1].data, m.segments)
    if name == "m.msh":
        # Gmsh 2.2 (not ANSYS, which meshio picks for .msh); region r is group r + 1
        assert (tmp_path / name).read_bytes().startswith(b"$MeshFormat\n2.2")
        np.testing.assert_array_equal(back.cell_data["gmsh:physical"][0], m.regions + 1)
        return
    key = {"m.mesh": "medit:ref"}.get(name, "region")
    np.testing.assert_array_equal(np.asarray(back.cell_data[key][0]).astype(int), m.regions)
    key = {"m.mesh": "medit:ref"}.get(name, "segment_marker")
    np.testing.assert_array_equal(np.asarray(back.cell_data[key][1]).astype(int), m.segment_markers)


def test_mesh_format_resolution():
    pytest.importorskip("meshio")
    assert mesh_format("a.poly") == "poly"
    assert mesh_format("a.1.NODE") == "node" and mesh_format("a.ele") == "node"
    assert mesh_format("a.msh") == "gmsh22"
    assert mesh_format("a.vtu") == "vtu"
    assert mesh_format("a.vol.gz") == "netgen"
    assert mesh_format("a.whatever", "gmsh") == "gmsh"


def test_unknown_format(tmp_path, two_region_mesh):
    pytest.importorskip("meshio")
    with pytest.raises(InvalidInputError, match=r"'m\.xyz'.*\.vtu"):
        two_region_mesh.write(tmp_path / "m.xyz")
    with pytest.raises(InvalidInputError, match="meshio cannot write"):
        two_region_mesh.write(tmp_path / "m.vtu", file_format="no-such-format")
    assert list(tmp_path.iterdir()) == []


def test_without_meshio(tmp_path, two_region_mesh, monkeypatch):
    monkeypatch.setitem(sys.modules, "meshio", None)  # import meshio now fails
    with pytest.raises(ModuleNotFoundError, match=r"pip install aftmesh\[io\]"):
        two_region_mesh.write(tmp_path / "m.vtu")
    two_region_mesh.write(tmp_path / "m.node")  # native formats still work
    two_region_mesh.write(tmp_path / "m.poly")
    assert {p.name for p in tmp_path.iterdir()} == {"m.node", "m.ele", "m.poly"}


# ------------------------------------------------------------------ WKT and GeoJSON


def test_read_wkt_and_mesh(tmp_path, checked):
    p = _write(
        tmp_path / "d.wkt",
        "POLYGON ((0 0, 2 0, 2 1, 0 1, 0 0), (0.5 0.25, 0.5 0.75, 1 0.75, 1 0.25, 0.5 0.25))\n",
    )
    geom = read_wkt(p)
    assert geom.geom_type == "Polygon" and geom.area == 1.75
    checked(aftmesh.generate(geom, size=0.1), domain_area=1.75)


def test_read_geojson_feature_collection_with_a_constraint(tmp_path, checked):
    p = _write(
        tmp_path / "d.geojson",
        """{"type": "FeatureCollection", "features": [
      {"type": "Feature", "properties": {},
       "geometry": {"type": "Polygon", "coordinates": [[[0, 0], [2, 0], [2, 1], [0, 1], [0, 0]]]}},
      {"type": "Feature", "properties": {},
       "geometry": {"type": "LineString", "coordinates": [[0.5, 0.5], [1.5, 0.5]]}}]}""",
    )
    geom = read_geojson(p)
    assert geom.geom_type == "GeometryCollection"
    mesh = checked(aftmesh.generate(geom, size=0.2), domain_area=2.0)
    # the constraint line is made of mesh segments
    P = mesh.points[mesh.segments]
    on_line = (
        (P[:, :, 1] == 0.5).all(axis=1)
        & (P[:, :, 0] >= 0.5).all(axis=1)
        & (P[:, :, 0] <= 1.5).all(axis=1)
    )
    assert np.isclose(np.abs(P[on_line, 1, 0] - P[on_line, 0, 0]).sum(), 1.0)


@pytest.mark.parametrize(
    "reader, name, text, fragment",
    [
        (read_wkt, "a.wkt", "POLYGON ((0 0, 1 1", "not a valid WKT"),
        (read_wkt, "a.wkt", "\n  \n", "empty"),
        (read_wkt, "a.wkt", "POLYGON EMPTY", "empty"),
        (read_geojson, "a.geojson", '{"type": "Polygon"}', "not a valid GeoJSON"),
        (read_geojson, "a.geojson", "", "empty"),
    ],
)
def test_bad_wkt_and_geojson(tmp_path, reader, name, text, fragment):
    p = _write(tmp_path / name, text)
    with pytest.raises(InvalidInputError, match=fragment) as info:
        reader(p)
    assert str(p) in str(info.value)


# ------------------------------------------------------------------ pictures


def test_save_png_and_plot_options(tmp_path, two_region_mesh):
    pytest.importorskip("matplotlib")
    from matplotlib.figure import Figure
    from matplotlib.image import imread

    from aftmesh.plotting import plot_mesh, save_png

    m = two_region_mesh
    save_png(m, tmp_path / "q.png", dpi=40, zoom=(0.8, 2.2, 0.3, 1.7))
    image = imread(tmp_path / "q.png")
    assert image.ndim == 3 and image.shape[0] > 100 and image.shape[1] == 320
    q = aftmesh.mesh.triangle_quality(m.points, m.triangles)
    for color_by in ("quality", "region", "none"):
        fig = Figure()
        ax = m.plot(ax=fig.add_subplot(), color_by=color_by)
        assert ax.get_title() == (
            f"{m.n_triangles} triangles, {m.n_points} points, "
            f"min angle {q['min_angle'].min():.1f}\N{DEGREE SIGN}"
        )
        assert ax.get_aspect() == 1.0
        # the segments, drawn once, on top
        assert sum(
            len(c.get_segments())
            for c in ax.collections
            if c.__class__.__name__ == "LineCollection"
        ) == len(m.segments)
        # a colorbar for quality and region only
        assert len(fig.axes) == (1 if color_by == "none" else 2)
    ax = plot_mesh(
        m,
        ax=Figure().add_subplot(),
        color_by="region",
        title="mine",
        show_segments=False,
        colorbar=False,
    )
    assert ax.get_title() == "mine" and len(ax.figure.axes) == 1
    faces = ax.collections[0].get_array()
    np.testing.assert_array_equal(faces, m.regions)  # regions 0, 1 -> indices 0, 1
    with pytest.raises(InvalidOptionError, match="color_by"):
        m.plot(ax=Figure().add_subplot(), color_by="angle")


def test_plotting_without_matplotlib(tmp_path, two_region_mesh, monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    from aftmesh.plotting import save_png

    with pytest.raises(ModuleNotFoundError, match=r"pip install aftmesh\[plot\]"):
        save_png(two_region_mesh, tmp_path / "x.png")
    with pytest.raises(ModuleNotFoundError, match=r"pip install aftmesh\[plot\]"):
        two_region_mesh.plot()
