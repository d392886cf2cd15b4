"""mipraster.Mesh: numpy in, dtypes and layouts, and every error path (checked before C++)."""
import sys
import types

import numpy as np
import pytest

import mipraster as mr

POSITIONS = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.5]]
TRIANGLES = [[0, 1, 2], [0, 2, 3]]


@pytest.mark.parametrize("dtype", [np.float64, np.float32, np.float16, np.int64, np.int32, np.int16, np.uint8])
def test_positions_of_any_real_dtype_become_float32(dtype):
    pos = (np.array(POSITIONS) * 2).astype(dtype)
    mesh = mr.Mesh(pos, TRIANGLES)
    assert mesh.positions.dtype == np.float32 and mesh.positions.shape == (4, 3)
    np.testing.assert_array_equal(mesh.positions, pos.astype(np.float32))


@pytest.mark.parametrize("dtype", [np.int8, np.int16, np.int32, np.int64, np.uint16, np.uint32, np.uint64])
def test_triangles_of_any_integer_dtype_become_uint32(dtype):
    mesh = mr.Mesh(POSITIONS, np.array(TRIANGLES, dtype=dtype))
    assert mesh.triangles.dtype == np.uint32 and mesh.triangles.shape == (2, 3)
    np.testing.assert_array_equal(mesh.triangles, TRIANGLES)


def test_lists_and_tuples_are_accepted():
    mesh = mr.Mesh(tuple(map(tuple, POSITIONS)), TRIANGLES, colors=[[1, 0, 0]] * 4)
    np.testing.assert_array_equal(mesh.positions, np.float32(POSITIONS))
    assert (mesh.vertex_count, mesh.triangle_count) == (4, 2)


def test_read_only_arrays_are_accepted_and_left_alone():
    positions = np.array(POSITIONS, dtype=np.float32)
    triangles = np.array(TRIANGLES, dtype=np.int64)
    for a in (positions, triangles):
        a.flags.writeable = False
    mesh = mr.Mesh(positions, triangles)
    np.testing.assert_array_equal(mesh.positions, positions)
    assert not positions.flags.writeable and not triangles.flags.writeable


def test_non_contiguous_and_fortran_order_arrays_keep_their_values():
    wide = np.zeros((4, 6))
    wide[:, ::2] = POSITIONS
    strided = wide[:, ::2]  # non-contiguous view
    assert not strided.flags.c_contiguous
    fortran = np.asfortranarray(np.array(TRIANGLES, dtype=np.int64))
    assert fortran.flags.f_contiguous and not fortran.flags.c_contiguous
    colors = np.asfortranarray(np.linspace(0, 1, 16).reshape(4, 4))
    mesh = mr.Mesh(strided, fortran, colors)
    np.testing.assert_array_equal(mesh.positions, np.float32(POSITIONS))
    np.testing.assert_array_equal(mesh.triangles, TRIANGLES)
    np.testing.assert_array_equal(mesh.colors, colors.astype(np.float32))
    reversed_rows = np.array(POSITIONS)[::-1]  # negative strides
    np.testing.assert_array_equal(mr.Mesh(reversed_rows, TRIANGLES).positions, np.float32(POSITIONS[::-1]))


def test_rgb_colors_get_alpha_one_and_rgba_colors_are_kept():
    rgb = np.array([[0.1, 0.2, 0.3]] * 4)
    mesh = mr.Mesh(POSITIONS, TRIANGLES, rgb)
    assert mesh.colors.shape == (4, 4) and mesh.colors.dtype == np.float32
    np.testing.assert_array_equal(mesh.colors[:, 3], 1.0)
    np.testing.assert_array_equal(mesh.colors[:, :3], rgb.astype(np.float32))
    rgba = np.array([[0.1, 0.2, 0.3, 0.4]] * 4, dtype=np.float32)
    np.testing.assert_array_equal(mr.Mesh(POSITIONS, TRIANGLES, rgba).colors, rgba)
    assert mr.Mesh(POSITIONS, TRIANGLES).colors is None


def test_mesh_holds_a_read_only_copy():
    pos = np.array(POSITIONS, dtype=np.float32)
    mesh = mr.Mesh(pos, TRIANGLES)
    pos[0, 0] = 42.0
    assert mesh.positions[0, 0] == 0.0  # the mesh copied the input
    for view in (mesh.positions, mesh.triangles):
        assert not view.flags.writeable
        with pytest.raises(ValueError):
            view[0, 0] = 1
        with pytest.raises(ValueError):
            view.setflags(write=True)


def test_empty_mesh():
    mesh = mr.Mesh(np.zeros((0, 3)), [])
    assert (mesh.vertex_count, mesh.triangle_count) == (0, 0)
    assert mesh.triangles.shape == (0, 3)


def test_repr():
    assert repr(mr.Mesh(POSITIONS, TRIANGLES)) == "Mesh(vertices=4, triangles=2)"
    assert repr(mr.Mesh(POSITIONS, TRIANGLES, np.ones((4, 3)))) == "Mesh(vertices=4, triangles=2, colors)"


# --- errors -------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "kwargs, words",
    [
        (dict(positions=np.zeros((4, 2))), ["positions", "(N, 3)", "(4, 2)"]),
        (dict(positions=np.zeros(12)), ["positions", "(N, 3)", "(12,)"]),
        (dict(positions=np.zeros((2, 2, 3))), ["positions", "(N, 3)", "(2, 2, 3)"]),
        (dict(triangles=np.zeros((2, 4), int)), ["triangles", "(T, 3)", "(2, 4)"]),
        (dict(triangles=[0, 1, 2]), ["triangles", "(T, 3)", "(3,)"]),
        (dict(colors=np.ones((3, 3))), ["colors", "(4, 3) or (4, 4)", "(3, 3)"]),
        (dict(colors=np.ones((4, 2))), ["colors", "(4, 3) or (4, 4)", "(4, 2)"]),
        (dict(positions=[[0, 0, 0], [1, 0]]), ["positions", "rectangular"]),
    ],
)
def test_wrong_shapes_raise_value_error_naming_argument_and_shapes(kwargs, words):
    args = dict(positions=POSITIONS, triangles=TRIANGLES, colors=None)
    args.update(kwargs)
    with pytest.raises(ValueError) as e:
        mr.Mesh(**args)
    for w in words:
        assert w in str(e.value)


@pytest.mark.parametrize(
    "kwargs, words",
    [
        (dict(positions=np.zeros((4, 3), dtype=bool)), ["positions", "bool"]),
        (dict(positions=np.zeros((4, 3), dtype=complex)), ["positions", "complex"]),
        (dict(positions=np.array([[0, 0, None]] * 4)), ["positions", "object"]),
        (dict(positions=[["a", "b", "c"]] * 4), ["positions", "str"]),
        (dict(triangles=np.array(TRIANGLES, dtype=np.float64)), ["triangles", "integers", "float64", "astype"]),
        (dict(triangles=np.array(TRIANGLES, dtype=bool)), ["triangles", "bool"]),
        (dict(colors=np.zeros((4, 3), dtype=bool)), ["colors", "bool"]),
    ],
)
def test_non_numeric_dtypes_raise_type_error(kwargs, words):
    args = dict(positions=POSITIONS, triangles=TRIANGLES, colors=None)
    args.update(kwargs)
    with pytest.raises(TypeError) as e:
        mr.Mesh(**args)
    for w in words:
        assert w in str(e.value)


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_positions_name_row_and_column(bad):
    pos = np.array(POSITIONS)
    pos[2, 1] = bad
    pos[3, 0] = bad  # only the first is reported
    with pytest.raises(ValueError, match=r"positions\[2, 1\] \(row 2, column 1\) is -?(nan|inf)"):
        mr.Mesh(pos, TRIANGLES)


def test_non_finite_colors_name_row_and_column():
    colors = np.ones((4, 4))
    colors[3, 2] = np.nan
    with pytest.raises(ValueError, match=r"colors\[3, 2\] \(row 3, column 2\) is nan"):
        mr.Mesh(POSITIONS, TRIANGLES, colors)


def test_float64_values_beyond_float32_range_are_refused():
    pos = np.array(POSITIONS)
    pos[1, 2] = 1e300
    with pytest.raises(ValueError, match=r"positions\[1, 2\].*float32"):
        mr.Mesh(pos, TRIANGLES)


def test_index_out_of_range_names_triangle_corner_and_vertex_count():
    with pytest.raises(ValueError) as e:
        mr.Mesh(POSITIONS, [[0, 1, 2], [0, 2, 4]])
    msg = str(e.value)
    assert "triangles[1, 2]" in msg and "triangle 1" in msg and "corner 2" in msg
    assert "= 4" in msg and "< 4" in msg and "vertex count" in msg


@pytest.mark.parametrize("dtype", [np.int8, np.int64])
def test_negative_index_is_refused(dtype):
    with pytest.raises(ValueError) as e:
        mr.Mesh(POSITIONS, np.array([[0, -1, 2]], dtype=dtype))
    msg = str(e.value)
    assert "triangles[0, 1]" in msg and "corner 1" in msg and "negative" in msg and "4" in msg


def test_huge_unsigned_index_is_out_of_range():
    with pytest.raises(ValueError, match=r"triangles\[0, 0\].*= 18446744073709551615"):
        mr.Mesh(POSITIONS, np.array([[2**64 - 1, 1, 2]], dtype=np.uint64))


def test_integer_colors_must_be_zero_or_one():
    with pytest.raises(ValueError, match=r"colors\[0, 0\].*255.*srgb_to_linear"):
        mr.Mesh(POSITIONS, TRIANGLES, np.full((4, 3), 255, dtype=np.uint8))


# --- Mesh.from_trimesh ------------------------------------------------------------------------------
# Duck-typed stand-ins cover every branch without trimesh; the real package is checked at the end.
# Oracle for colours: the sRGB decoding formula of IEC 61966-2-1, written out here.


def srgb_decode(c):
    c = np.asarray(c, dtype=np.float64)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


NORMALS = [[0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.0, 0.6, 0.8], [0.0, 0.6, 0.8]]
UVS_UP = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.25, 0.9]]  # trimesh/OBJ: v grows upwards
RGBA8 = np.array([[255, 0, 0, 255], [188, 128, 0, 128], [0, 255, 64, 0], [10, 20, 30, 51]], dtype=np.uint8)


def fake_mesh(visual=None, normals=True):
    mesh = types.SimpleNamespace(vertices=np.array(POSITIONS), faces=np.array(TRIANGLES, dtype=np.int64))
    if normals:
        mesh.vertex_normals = np.array(NORMALS)
    if visual is not None:
        mesh.visual = visual
    return mesh


def expected_colors(rgba8):
    rgba = np.asarray(rgba8, dtype=np.float64) / 255.0
    alpha = rgba[:, 3:4] if rgba.shape[1] == 4 else np.ones((len(rgba), 1))
    return np.concatenate([srgb_decode(rgba[:, :3]) * alpha, alpha], axis=1)


def test_from_trimesh_takes_positions_faces_normals_and_flips_v():
    texture = types.SimpleNamespace(kind="texture", uv=np.array(UVS_UP))
    mesh = mr.Mesh.from_trimesh(fake_mesh(texture))
    np.testing.assert_array_equal(mesh.positions, np.float32(POSITIONS))
    np.testing.assert_array_equal(mesh.triangles, TRIANGLES)
    assert mesh.triangles.dtype == np.uint32
    np.testing.assert_allclose(mesh.normals, NORMALS)
    np.testing.assert_allclose(mesh.uvs, [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.25, 0.1]], atol=1e-7)
    assert mesh.colors is None  # a texture visual has no vertex colours


def test_from_trimesh_needs_only_vertices_and_faces():
    mesh = mr.Mesh.from_trimesh(fake_mesh(normals=False))
    assert (mesh.vertex_count, mesh.triangle_count) == (4, 2)
    assert mesh.normals is None and mesh.uvs is None and mesh.colors is None
    no_uv = mr.Mesh.from_trimesh(fake_mesh(types.SimpleNamespace(kind="texture", uv=None)))
    assert no_uv.uvs is None and no_uv.colors is None


@pytest.mark.parametrize("kind", ["vertex", "face"])
def test_from_trimesh_decodes_srgb8_vertex_colours_to_linear_premultiplied(kind):
    visual = types.SimpleNamespace(kind=kind, vertex_colors=RGBA8)
    mesh = mr.Mesh.from_trimesh(fake_mesh(visual))
    np.testing.assert_allclose(mesh.colors, expected_colors(RGBA8), rtol=1e-6, atol=1e-7)
    assert mesh.colors[1, 3] == np.float32(128 / 255)
    assert abs(mesh.colors[1, 0] / mesh.colors[1, 3] - 0.5) < 4e-3  # sRGB 188 is linear ½, then premultiplied
    np.testing.assert_array_equal(mesh.colors[2], 0.0)  # alpha 0: all zero
    assert mr.Mesh.from_trimesh(fake_mesh(visual), colors=False).colors is None


def test_from_trimesh_colour_variants():
    rgb8 = RGBA8[:, :3]
    mesh = mr.Mesh.from_trimesh(fake_mesh(types.SimpleNamespace(kind="vertex", vertex_colors=rgb8)))
    np.testing.assert_allclose(mesh.colors, expected_colors(rgb8), rtol=1e-6, atol=1e-7)
    np.testing.assert_array_equal(mesh.colors[:, 3], 1.0)
    floats = RGBA8 / 255.0  # float colours are sRGB in [0, 1], as in trimesh
    mesh = mr.Mesh.from_trimesh(fake_mesh(types.SimpleNamespace(kind="vertex", vertex_colors=floats)))
    np.testing.assert_allclose(mesh.colors, expected_colors(RGBA8), rtol=1e-6, atol=1e-7)
    # kind None: trimesh's default colours, not the mesh's: not taken.
    default = types.SimpleNamespace(kind=None, vertex_colors=np.full((4, 4), 102, np.uint8))
    assert mr.Mesh.from_trimesh(fake_mesh(default)).colors is None


def test_from_trimesh_errors():
    with pytest.raises(TypeError, match="colors"):
        mr.Mesh.from_trimesh(fake_mesh(), colors="yes")
    bad = types.SimpleNamespace(kind="vertex", vertex_colors=np.full((4, 4), 256, np.int32))
    with pytest.raises(ValueError, match=r"vertex_colors\[0, 0\] = 256"):
        mr.Mesh.from_trimesh(fake_mesh(bad))
    nan = fake_mesh()
    nan.vertices = nan.vertices.copy()
    nan.vertices[1, 2] = np.nan
    with pytest.raises(ValueError, match=r"positions\[1, 2\]"):
        mr.Mesh.from_trimesh(nan)
    short_uv = types.SimpleNamespace(uv=np.zeros((3, 2)))
    with pytest.raises(ValueError, match="uvs"):
        mr.Mesh.from_trimesh(fake_mesh(short_uv))


def test_from_trimesh_without_trimesh_installed_raises_import_error_with_hint(monkeypatch):
    monkeypatch.setitem(sys.modules, "trimesh", None)  # `import trimesh` now raises ImportError
    with pytest.raises(ImportError, match="pip install trimesh"):
        mr.Mesh.from_trimesh("model.obj")
    assert mr.Mesh.from_trimesh(fake_mesh()).vertex_count == 4  # duck-typed meshes need no trimesh


def test_from_trimesh_flattens_a_scene_and_refuses_other_objects(monkeypatch):
    class FakeScene:  # trimesh < 4.5 only has dump(concatenate=True)
        def dump(self, concatenate=False):
            assert concatenate
            return fake_mesh()

    class NewFakeScene(FakeScene):
        def to_geometry(self):
            return fake_mesh(normals=False)

    monkeypatch.setitem(sys.modules, "trimesh", types.SimpleNamespace(Scene=FakeScene))
    assert mr.Mesh.from_trimesh(FakeScene()).normals is not None
    assert mr.Mesh.from_trimesh(NewFakeScene()).normals is None
    with pytest.raises(TypeError, match="trimesh.Trimesh.*int"):
        mr.Mesh.from_trimesh(42)


def test_from_trimesh_with_the_real_package(tmp_path):
    trimesh = pytest.importorskip(
        "trimesh", reason="trimesh is an optional dependency (pip install trimesh); the duck-typed "
                          "from_trimesh tests cover the conversion without it")
    # Vertex colours on a box; normals are trimesh's own.
    box = trimesh.creation.box()
    rgba8 = np.random.default_rng(1).integers(0, 256, (len(box.vertices), 4), dtype=np.uint8)
    box.visual.vertex_colors = rgba8
    mesh = mr.Mesh.from_trimesh(box)
    np.testing.assert_allclose(mesh.positions, box.vertices, atol=1e-7)
    np.testing.assert_array_equal(mesh.triangles, box.faces)
    np.testing.assert_allclose(mesh.normals, box.vertex_normals, atol=1e-7)
    np.testing.assert_allclose(mesh.colors, expected_colors(rgba8), rtol=1e-6, atol=1e-7)
    assert mesh.uvs is None
    assert mr.Mesh.from_trimesh(trimesh.creation.box()).colors is None  # default colours are not taken

    # A hand-written OBJ: "vt 0.25 0.1" is near the bottom of the image, so v' = 0.9.
    obj = tmp_path / "quad.obj"
    obj.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                   "vt 0 0\nvt 1 0\nvt 1 1\nvt 0.25 0.1\n"
                   "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n")
    loaded = trimesh.load(obj, force="mesh", process=False)
    assert isinstance(loaded.visual, trimesh.visual.TextureVisuals)
    mesh = mr.Mesh.from_trimesh(loaded)
    by_position = {tuple(p): tuple(uv) for p, uv in zip(mesh.positions.tolist(), mesh.uvs.tolist())}
    expected = {(0, 0, 0): (0, 1), (1, 0, 0): (1, 1), (1, 1, 0): (1, 0), (0, 1, 0): (0.25, 0.9)}
    for p, uv in expected.items():
        np.testing.assert_allclose(by_position[p], uv, atol=1e-6)

    # A scene of two meshes becomes one.
    scene = trimesh.Scene([trimesh.creation.box(), trimesh.creation.icosphere(subdivisions=1)])
    flat = mr.Mesh.from_trimesh(scene)
    assert flat.triangle_count == 12 + 80
    with pytest.raises(TypeError, match="trimesh"):
        mr.Mesh.from_trimesh(42)
