"""Output for other tools: VTK snapshots and series, PNG snapshots, GIF animations."""
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from demfem.errors import InvalidParameterError, ShapeError
from demfem.io import write_pvd, write_vtp
from demfem.plots import animate_table, plot_table_snapshot
from demfem.scenes import AccumulationTable


@pytest.fixture(scope="module")
def scene():
    return AccumulationTable().build()


def test_vtp_holds_points_and_point_data(tmp_path):
    pos = np.array([[0.0, 0.0, 0.008], [0.1, 0.2, 0.008], [1 / 3, 0.5, 0.008]])
    path = write_vtp(tmp_path / "frame.vtp", pos, {
        "radius": np.full(3, 0.008), "tag": np.array([0, 5, 1], np.int32),
        "velocity": np.array([[0.2, 0, 0], [0, 0.1, 0], [0, 0, 0]]),
        "present": np.array([True, True, False])})
    root = ET.parse(path).getroot()
    assert root.get("type") == "PolyData"
    piece = root.find("PolyData/Piece")
    assert piece.get("NumberOfPoints") == "3" and piece.get("NumberOfVerts") == "3"
    points = np.array(piece.find("Points/DataArray").text.split(), float).reshape(-1, 3)
    assert np.array_equal(points, pos)  # 17 digits: exact round trip
    arrays = {a.get("Name"): a for a in piece.find("PointData")}
    assert arrays["tag"].get("type") == "Int32"
    assert arrays["tag"].text.split() == ["0", "5", "1"]
    assert arrays["velocity"].get("NumberOfComponents") == "3"
    assert arrays["present"].get("type") == "UInt8"
    offsets = piece.find("Verts/DataArray[@Name='offsets']").text.split()
    assert offsets == ["1", "2", "3"]
    assert [p.name for p in tmp_path.iterdir()] == ["frame.vtp"]  # no temporary left over


def test_vtp_rejects_bad_input(tmp_path):
    with pytest.raises(ShapeError, match="positions"):
        write_vtp(tmp_path / "a.vtp", np.zeros((3, 2)))
    with pytest.raises(ShapeError, match=r"point_data\['radius'\]"):
        write_vtp(tmp_path / "a.vtp", np.zeros((3, 3)), {"radius": np.zeros(2)})
    with pytest.raises(InvalidParameterError, match="finite"):
        write_vtp(tmp_path / "a.vtp", np.full((1, 3), np.nan))
    assert not list(tmp_path.iterdir())


def test_pvd_lists_frames_with_times(tmp_path):
    path = write_pvd(tmp_path / "run.pvd", [(0.0, "f0.vtp"), (0.05, "f1.vtp")])
    sets = ET.parse(path).getroot().findall("Collection/DataSet")
    assert [(float(d.get("timestep")), d.get("file")) for d in sets] == \
        [(0.0, "f0.vtp"), (0.05, "f1.vtp")]


def test_snapshot_png(tmp_path, scene):
    path = plot_table_snapshot(tmp_path / "table.png", scene, time=0.5, dpi=40)
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 5000
    moved = scene.positions.copy()
    moved[:10] = np.nan  # removed spheres are skipped
    plot_table_snapshot(tmp_path / "later.png", scene, moved, time=1.0, dpi=40)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["later.png", "table.png"]
    with pytest.raises(ShapeError):
        plot_table_snapshot(tmp_path / "x.png", scene, moved[:5])


def test_animation_gif(tmp_path, scene):
    from PIL import Image

    frames = np.stack([scene.positions + [0.01 * k, 0, 0] for k in range(3)])
    path = animate_table(tmp_path / "movie.gif", scene, frames, [0.0, 0.5, 1.0], fps=5, dpi=30)
    with Image.open(path) as image:
        assert image.format == "GIF" and image.n_frames == 3
    assert [p.name for p in tmp_path.iterdir()] == ["movie.gif"]


def test_triangle_meshes_are_written_as_vtu_and_bad_ones_refused(tmp_path):
    """`write_vtu_triangles` (the shells' VTK): points, triangles, point and cell data round
    trip through the XML; wrong shapes and out-of-range nodes are refused naming the field."""
    import xml.etree.ElementTree as ET

    import numpy as np
    import pytest

    from demfem.errors import InvalidParameterError, ShapeError
    from demfem.io.vtk import write_vtu_triangles

    pts = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])
    tri = np.array([[0, 1, 2], [1, 3, 2]])
    path = write_vtu_triangles(tmp_path / "t.vtu", pts, tri, {"u": np.ones((4, 3))},
                               {"s": np.array([1.5, -2.0])})
    piece = ET.parse(path).getroot().find("UnstructuredGrid/Piece")
    assert (piece.get("NumberOfPoints"), piece.get("NumberOfCells")) == ("4", "2")
    assert piece.find("Cells/DataArray[@Name='types']").text.split() == ["5", "5"]
    assert piece.find("Cells/DataArray[@Name='connectivity']").text.split() == \
        ["0", "1", "2", "1", "3", "2"]
    assert [float(x) for x in piece.find("CellData/DataArray").text.split()] == [1.5, -2.0]
    with pytest.raises(InvalidParameterError, match="triangles"):
        write_vtu_triangles(tmp_path / "b.vtu", pts, np.array([[0, 1, 7]]))
    with pytest.raises(ShapeError, match="cell_data"):
        write_vtu_triangles(tmp_path / "b.vtu", pts, tri, cell_data={"s": np.ones(3)})
    with pytest.raises(ShapeError, match="points"):
        write_vtu_triangles(tmp_path / "b.vtu", pts[:, :2], tri)
