"""Export with tags: every format Mesh.write documents, read back by meshio, Triangle's
reader and scikit-fem's loader, keeps the points, triangles, regions, segments and the
segments' markers and tags; and the README's finite-element example runs."""

import copy
import re
import sys
from pathlib import Path

import numpy as np
import pytest
from shapely.geometry import Point, Polygon, box

import aftmesh
from aftmesh.io import gmsh_physical_groups, read_poly

ROOT = Path(__file__).resolve().parents[1]
SIDES = {"left": 1, "right": 2, "bottom": 3, "top": 4}


def with_tags(mesh, tags, tag_names):
    """A copy of ``mesh`` with segment tags, as ``generate(boundary_tags=...)`` gives
    them (set by hand here, so the export is tested whatever made the tags)."""
    out = copy.copy(mesh)
    object.__setattr__(out, "segment_tags", np.asarray(tags, dtype=np.int32))
    object.__setattr__(out, "tag_names", dict(tag_names))
    return out


def side_tags(mesh, width, height):
    """Tag of each segment: the side of the rectangle it lies on, 0 inside."""
    mid = mesh.points[mesh.segments].mean(axis=1)
    tags = np.zeros(len(mid), dtype=np.int32)
    tags[mid[:, 0] == 0] = SIDES["left"]
    tags[mid[:, 0] == width] = SIDES["right"]
    tags[mid[:, 1] == 0] = SIDES["bottom"]
    tags[mid[:, 1] == height] = SIDES["top"]
    return tags


@pytest.fixture(scope="module")
def tagged():
    """A 3 x 2 box with named sides, a round hole (untagged boundary) and a square
    core of region 1 (an untagged interface)."""
    core = box(1, 0.5, 2, 1.5)
    outer = Polygon(
        box(0, 0, 3, 2).exterior.coords,
        [core.exterior.coords, Point(2.5, 1).buffer(0.3, 8).exterior.coords],
    )
    mesh = aftmesh.generate([outer, core], size=0.2)
    aftmesh.checks.check_mesh(mesh, domain_area=outer.area + core.area)
    tags = side_tags(mesh, 3, 2)
    assert set(np.unique(tags).tolist()) == {0, 1, 2, 3, 4}
    out = with_tags(mesh, tags, SIDES)
    if getattr(out, "segment_sources", None) is None:
        # the input edge of each segment: the exterior ring's edges go right, top,
        # left, bottom (the others are left unknown here: only the export is tested)
        edge_of_side = np.array([-1, 2, 0, 3, 1])
        object.__setattr__(out, "segment_sources", edge_of_side[tags].astype(np.int32))
    return out


def _pairs(edges):
    return set(map(tuple, np.sort(np.asarray(edges), axis=1).tolist()))


def _boundary_segment(mesh):
    """Whether each segment is an edge of one triangle only."""
    ti, k = np.nonzero(mesh.neighbors < 0)
    outside = _pairs(np.c_[mesh.triangles[ti, (k + 1) % 3], mesh.triangles[ti, (k + 2) % 3]])
    return np.array([p in outside for p in map(tuple, np.sort(mesh.segments, axis=1).tolist())])


# ------------------------------------------------------------------ meshio formats

MESHIO_FORMATS = ["tagged.msh", "tagged.vtu", "tagged.xdmf", "tagged.vtk", "tagged.mesh"]


@pytest.mark.parametrize("name", MESHIO_FORMATS)
def test_meshio_formats_keep_regions_segments_markers_and_tags(tmp_path, tagged, name):
    meshio = pytest.importorskip("meshio")
    if name.endswith(".xdmf"):
        pytest.importorskip("h5py")
    m = tagged
    m.write(tmp_path / name)
    back = meshio.read(tmp_path / name)
    np.testing.assert_array_equal(back.points[:, :2], m.points)
    assert [b.type for b in back.cells] == ["triangle", "line"]
    np.testing.assert_array_equal(back.cells[0].data, m.triangles)
    np.testing.assert_array_equal(back.cells[1].data, m.segments)
    data = {k: [np.asarray(v).astype(int) for v in val] for k, val in back.cell_data.items()}
    if name.endswith(".msh"):
        tag_of = {name: int(v[0]) for name, v in back.field_data.items()}
        name_of = {v: k for k, v in tag_of.items()}
        # one name per group, no number used twice (even across dimensions)
        assert len(name_of) == len(tag_of)
        tri, seg = data["gmsh:physical"]
        np.testing.assert_array_equal(tri, m.regions + 1)
        assert [name_of[t] for t in tri[:5]] == [f"region_{r}" for r in m.regions[:5]]
        by_tag = {k: n for n, k in SIDES.items()} | {0: "untagged"}
        assert [name_of[t] for t in seg] == [by_tag[t] for t in m.segment_tags]
        assert {int(v[1]) for k, v in back.field_data.items() if k in SIDES} == {1}
        return
    if name.endswith(".mesh"):
        # medit keeps one reference per cell: regions and segment markers
        np.testing.assert_array_equal(data["medit:ref"][0], m.regions)
        np.testing.assert_array_equal(data["medit:ref"][1], m.segment_markers)
        return
    np.testing.assert_array_equal(data["region"][0], m.regions)
    assert (data["region"][1] == -1).all()
    np.testing.assert_array_equal(data["segment_marker"][1], m.segment_markers)
    np.testing.assert_array_equal(data["segment_tag"][1], m.segment_tags)
    assert (data["segment_tag"][0] == 0).all()
    np.testing.assert_array_equal(data["segment_source"][1], m.segment_sources)
    assert (data["segment_source"][0] == -1).all()


def test_native_formats_keep_what_they_hold(tmp_path, tagged):
    triangle = pytest.importorskip("triangle")
    m = tagged
    m.write(tmp_path / "tagged.poly")
    d = read_poly(tmp_path / "tagged.poly")
    np.testing.assert_array_equal(d["vertices"], m.points)
    np.testing.assert_array_equal(d["segments"], m.segments)
    np.testing.assert_array_equal(d["segment_markers"], m.segment_markers)
    assert len(d["holes"]) == 1 and sorted(d["regions"][:, 2].tolist()) == [0, 1]
    m.write(tmp_path / "tagged.ele")
    ref = triangle.load(str(tmp_path), "tagged")
    np.testing.assert_array_equal(ref["vertices"], m.points)
    np.testing.assert_array_equal(ref["triangles"], m.triangles)
    np.testing.assert_array_equal(ref["triangle_attributes"].ravel(), m.regions)


def test_meshes_without_tags_export_their_markers(tmp_path, checked):
    meshio = pytest.importorskip("meshio")
    m = checked(aftmesh.generate(box(0, 0, 2, 2).difference(box(0.5, 0.5, 1, 1)), size=0.4))
    assert getattr(m, "segment_tags", None) is None
    m.write(tmp_path / "m.msh")
    m.write(tmp_path / "m.vtu")
    back = meshio.read(tmp_path / "m.msh")
    name_of = {int(v[0]): k for k, v in back.field_data.items()}
    seg = back.cell_data["gmsh:physical"][1]
    # a shapely domain's marker is its ring, named after it
    names = np.array(m.info["sources"])[m.segment_markers]
    assert [name_of[t] for t in seg] == names.tolist()
    assert set(names) == {"the polygon, exterior ring", "the polygon, hole 0"}
    vtu = meshio.read(tmp_path / "m.vtu")
    assert "segment_tag" not in vtu.cell_data
    np.testing.assert_array_equal(vtu.cell_data["segment_marker"][1], m.segment_markers)


def test_physical_groups_of_markers_without_names(checked):
    # a dict domain's markers are the user's own numbers: named by number, after the
    # region groups, counted so that marker 0 is not group 0 (no group in Gmsh)
    square = {
        "vertices": [(0, 0), (1, 0), (1, 1), (0, 1)],
        "segments": [(0, 1), (1, 2), (2, 3), (3, 0)],
        "segment_markers": [0, 7, 7, -1],
    }
    m = checked(aftmesh.generate(square, size=0.5))
    tri, seg, names = gmsh_physical_groups(m)
    assert (tri == 1).all()
    np.testing.assert_array_equal(seg, 1 + m.segment_markers + 2)
    assert {k: v.tolist() for k, v in names.items()} == {
        "region_0": [1, 2],
        "segment_marker_-1": [2, 1],
        "segment_marker_0": [3, 1],
        "segment_marker_7": [10, 1],
    }


def test_every_group_keeps_a_name_of_its_own(tagged):
    m = with_tags(tagged, np.minimum(tagged.segment_tags, 1), {"untagged": 1})
    _, seg, names = gmsh_physical_groups(m)
    assert {k: v.tolist() for k, v in names.items()} == {
        "region_0": [1, 2],
        "region_1": [2, 2],
        "untagged": [3, 1],
        "untagged_4": [4, 1],
    }
    np.testing.assert_array_equal(seg, np.where(m.segment_tags == 1, 3, 4))


def test_negative_regions_still_get_positive_groups(checked):
    square = {
        "vertices": [(0, 0), (2, 0), (2, 1), (0, 1), (1, 0), (1, 1)],
        "segments": [(0, 4), (4, 1), (1, 2), (2, 5), (5, 3), (3, 0), (4, 5)],
        "regions": [(0.5, 0.5, -3), (1.5, 0.5, 2)],
    }
    m = checked(aftmesh.generate(square, size=0.5))
    tri, seg, names = gmsh_physical_groups(m)
    np.testing.assert_array_equal(tri, m.regions + 4)
    assert seg.min() > tri.max()
    assert names["region_-3"].tolist() == [1, 2] and names["region_2"].tolist() == [6, 2]


def test_xdmf_without_h5py_says_what_to_install(tmp_path, tagged, monkeypatch):
    pytest.importorskip("meshio")
    monkeypatch.setitem(sys.modules, "h5py", None)
    with pytest.raises(ModuleNotFoundError, match=r"needs h5py: pip install aftmesh\[io\]"):
        tagged.write(tmp_path / "x.xdmf")


def test_io_extra_has_what_every_advertised_format_needs():
    import tomllib

    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"][
        "optional-dependencies"
    ]
    names = {k: {re.split(r"[<>=!~ ]", r)[0] for r in v} for k, v in extras.items()}
    assert {"meshio", "h5py"} <= names["io"]
    assert {"meshio", "h5py", "scikit-fem"} <= names["test"]


# ------------------------------------------------------------------ scikit-fem


def test_scikit_fem_finds_the_tagged_boundaries_and_the_regions(tmp_path, tagged):
    skfem = pytest.importorskip("skfem")
    pytest.importorskip("meshio")
    m = tagged
    m.write(tmp_path / "tagged.msh")
    fem = skfem.MeshTri.load(tmp_path / "tagged.msh")
    np.testing.assert_array_equal(fem.p.T, m.points)
    # scikit-fem sorts each triangle's vertices
    np.testing.assert_array_equal(fem.t.T, np.sort(m.triangles, axis=1))
    assert set(fem.subdomains) == {"region_0", "region_1"}
    for r in (0, 1):
        np.testing.assert_array_equal(
            np.sort(fem.subdomains[f"region_{r}"]), np.flatnonzero(m.regions == r)
        )
    # scikit-fem keeps boundary facets only: the interface is untagged and inside
    on_boundary = _boundary_segment(m)
    assert set(fem.boundaries) == {*SIDES, "untagged"}
    for name, k in {**SIDES, "untagged": 0}.items():
        found = _pairs(fem.facets[:, fem.boundaries[name]].T)
        assert found == _pairs(m.segments[(m.segment_tags == k) & on_boundary]), name
        assert found


def test_poisson_with_a_dirichlet_side_from_the_exported_file(tmp_path, checked):
    """The README example's export half, on tags set by hand: -Δu = 1 on the unit
    square, u = 0 on the left side, natural conditions elsewhere; the exact solution
    is x - x²/2."""
    skfem = pytest.importorskip("skfem")
    pytest.importorskip("meshio")
    from skfem.helpers import dot, grad

    mesh = checked(aftmesh.generate(box(0, 0, 1, 1), size=0.1))
    tags = (mesh.points[mesh.segments].mean(axis=1)[:, 0] == 0).astype(np.int32)
    mesh = with_tags(mesh, tags, {"left": 1})
    mesh.write(tmp_path / "square.msh")
    fem = skfem.MeshTri.load(tmp_path / "square.msh")
    basis = skfem.Basis(fem, skfem.ElementTriP1())
    laplace = skfem.BilinearForm(lambda u, v, _: dot(grad(u), grad(v)))
    one = skfem.LinearForm(lambda v, _: 1.0 * v)
    fixed = basis.get_dofs("left").all()
    np.testing.assert_array_equal(np.sort(fixed), np.unique(mesh.segments[tags == 1]))
    u = skfem.solve(*skfem.condense(laplace.assemble(basis), one.assemble(basis), D=fixed))
    x = mesh.points[:, 0]
    assert (u[fixed] == 0).all() and (u[x > 0] > 0).all()
    # P1 on a mesh of size 0.1: the nodal error is of the order h^2 / 10
    assert np.abs(u - (x - x * x / 2)).max() < 2e-3


# ------------------------------------------------------------------ the README example


def readme_example(marker: str) -> str:
    """The code block after ``<!-- readme-example: marker -->`` in README.md."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    found = re.search(
        rf"<!-- readme-example: {re.escape(marker)} -->\s*```python\n(.*?)```", text, re.DOTALL
    )
    assert found, f"README.md has no code block marked readme-example: {marker}"
    return found.group(1)


def test_readme_poisson_example_runs(tmp_path, monkeypatch, capsys):
    pytest.importorskip("skfem")
    pytest.importorskip("meshio")
    monkeypatch.chdir(tmp_path)
    code = readme_example("poisson")
    namespace: dict = {}
    exec(compile(code, "README.md[poisson]", "exec"), namespace)  # noqa: S102 (our README)
    out = capsys.readouterr().out
    expected = re.search(r"# prints: (.*)", code).group(1)
    assert out.strip() == expected
    mesh, u, fixed = namespace["mesh"], namespace["u"], namespace["fixed"]
    aftmesh.checks.check_mesh(mesh, domain_area=1.0)
    x = mesh.points[:, 0]
    np.testing.assert_array_equal(np.sort(fixed), np.flatnonzero(x == 0))
    assert (u[x > 0] > 0).all()
    assert np.abs(u - (x - x * x / 2)).max() < 2e-3
    # the file it wrote has the same side, for scikit-fem
    import skfem

    fem = skfem.MeshTri.load(tmp_path / "square.msh")
    assert _pairs(fem.facets[:, fem.boundaries["left"]].T) == _pairs(
        mesh.segments[namespace["left"]]
    )
