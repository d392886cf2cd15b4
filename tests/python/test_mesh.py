"""mipraster.Mesh: numpy in, dtypes and layouts, and every error path (checked before C++)."""
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
