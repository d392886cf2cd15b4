"""glTF EXT_mesh_gpu_instancing: one draw per instance and primitive, at world × T·R·S of the instance.
The oracles are numpy's matrix products (with the quaternion's rotation matrix written out here) and
renders of the same instances written as plain nodes."""
import json
import math
import warnings

import numpy as np
import pytest

import mipraster as mr
from test_scene_file import data_uri, load_warning_texts

# A small quad in z = 0, counter-clockwise seen from +z (front-facing for the camera on +z), with a
# colour per corner so that a rotation shows in the render.
QUAD = np.float32([[-0.1, -0.1, 0], [0.1, -0.1, 0], [0.1, 0.1, 0], [-0.1, 0.1, 0]])
QUAD_COLORS = np.float32([[1, 0, 0, 1], [0, 1, 0, 1], [0, 0, 1, 1], [1, 1, 0, 1]])
QUAD_INDICES = np.uint16([0, 1, 2, 0, 2, 3])

S45 = math.sqrt(0.5)
# Four instances: a translation only; a rotation by 90 degrees about z only; a non-uniform scale
# only; and all three, with a rotation about a skew axis.
TRANSLATION = np.float32([[-0.5, 0.5, 0], [0, 0, 0], [0, 0, 0], [0.5, -0.4, 0.1]])
ROTATION = np.float32([[0, 0, 0, 1], [0, 0, S45, S45], [0, 0, 0, 1], [0.2, 0.3, 0.5, 0.787]])  # x, y, z, w
SCALE = np.float32([[1, 1, 1], [1, 1, 1], [1.5, 0.5, 1], [0.8, 1.3, 1]])
ROTATION[3] /= np.linalg.norm(ROTATION[3])
INSTANCE_VALUES = {"TRANSLATION": TRANSLATION, "ROTATION": ROTATION, "SCALE": SCALE}
# Instances 0 to 2 sit at different places: the ones without translation are moved by the node.
NODE = {"translation": [0.05, -0.05, 0], "scale": [1.2, 0.8, 1]}


def quaternion_matrix(x, y, z, w):
    """The rotation of the unit quaternion (x, y, z, w) (normalized first), as a 4x4 matrix acting on
    column vectors: the textbook formula, written out."""
    n = math.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = x / n, y / n, z / n, w / n
    m = np.eye(4)
    m[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                 [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                 [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    return m


def trs(translation=(0, 0, 0), rotation=(0, 0, 0, 1), scale=(1, 1, 1)):
    t = np.eye(4)
    t[:3, 3] = np.float64(translation)
    return t @ quaternion_matrix(*np.float64(rotation)) @ np.diag([*np.float64(scale), 1.0])


def test_oracle_rotates_x_to_y_for_a_quarter_turn_about_z():
    np.testing.assert_allclose(quaternion_matrix(0, 0, S45, S45)[:3, :3], [[0, -1, 0], [1, 0, 0], [0, 0, 1]],
                               atol=1e-15)


def write_doc(path, nodes, roots, chunks=(), accessors=(), extra=None):
    """A glTF file with the quad as mesh 0 (accessors 0 to 2), then `accessors` over `chunks` (one
    bufferView each, numbered from 3), the given nodes (scene roots `roots`) and an orthographic
    camera on the z axis at z = 5, seeing [-1, 1]^2 (the last node)."""
    buf, views = b"", []
    for chunk in [QUAD.tobytes(), QUAD_COLORS.tobytes(), QUAD_INDICES.tobytes(), *chunks]:
        views.append({"buffer": 0, "byteOffset": len(buf), "byteLength": len(chunk)})
        buf += chunk + b"\0" * (-len(chunk) % 4)
    doc = {
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": list(roots) + [len(nodes)]}],
        "nodes": list(nodes) + [{"camera": 0, "translation": [0, 0, 5]}],
        "cameras": [{"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 10}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "COLOR_0": 1}, "indices": 2}]}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"},
                      {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC4"},
                      {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}, *accessors],
        "bufferViews": views,
        "buffers": [{"byteLength": len(buf), "uri": data_uri(buf)}],
    }
    doc.update(extra or {})
    path.write_text(json.dumps(doc))
    return path


def write_instanced(path, values, node=None, required=False, **edits):
    """The quad on node 0 ('trees', with NODE's transform) with EXT_mesh_gpu_instancing attributes
    `values` ({name: array}, float VEC3/VEC4 accessors 3, 4, ... in that order); `edits` maps an
    attribute name to changes of its accessor (e.g. a component type)."""
    chunks, accessors, attributes = [], [], {}
    for k, (name, array) in enumerate(values.items()):
        chunks.append(np.ascontiguousarray(array).tobytes())
        kind = "VEC4" if array.shape[1] == 4 else "VEC3"
        component = {np.dtype(np.float32): 5126, np.dtype(np.int8): 5120, np.dtype(np.int16): 5122}[array.dtype]
        accessors.append({"bufferView": 3 + k, "componentType": component, "count": len(array), "type": kind,
                          **({"normalized": True} if component != 5126 else {}), **edits.get(name, {})})
        attributes[name] = 3 + k
    node = dict(NODE if node is None else node, mesh=0, name="trees",
                extensions={"EXT_mesh_gpu_instancing": {"attributes": attributes}})
    extra = {"extensionsUsed": ["EXT_mesh_gpu_instancing"]}
    if required:
        extra["extensionsRequired"] = ["EXT_mesh_gpu_instancing"]
    return write_doc(path, [node], [0], chunks, accessors, extra)


def load_quietly(path):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # an instanced file the loader reads fully gives no warning
        return mr.load_scene(path)


CASES = {"translation": ["TRANSLATION"], "rotation": ["ROTATION"], "scale": ["SCALE"],
         "mix": ["TRANSLATION", "ROTATION", "SCALE"], "rotation_scale": ["SCALE", "ROTATION"]}


@pytest.mark.parametrize("case", sorted(CASES))
def test_instances_are_draws_at_node_world_times_their_trs(tmp_path, case):
    values = {name: INSTANCE_VALUES[name] for name in CASES[case]}
    scene, _ = load_quietly(write_instanced(tmp_path / "instanced.gltf", values, required=True))
    assert len(scene.draws) == len(TRANSLATION)
    node = trs(NODE["translation"], scale=NODE["scale"])
    for i, draw in enumerate(scene.draws):
        parts = {name.lower(): values[name][i] for name in values}  # missing attributes: the identity
        np.testing.assert_allclose(draw.model, node @ trs(**parts), rtol=0, atol=1e-12, err_msg=f"instance {i}")
        np.testing.assert_array_equal(draw.mesh.positions, QUAD)


def test_quarter_turn_instance_maps_the_quads_corners_as_expected(tmp_path):
    # Independent of the quaternion formula: a quarter turn about z takes (x, y) to (-y, x).
    scene, _ = load_quietly(write_instanced(tmp_path / "turn.gltf", {"ROTATION": ROTATION[1:2]}, node={}))
    corners = np.c_[QUAD, np.ones(4)] @ scene.draws[0].model.T
    np.testing.assert_allclose(corners[:, :3], np.c_[-QUAD[:, 1], QUAD[:, 0], QUAD[:, 2]], atol=1e-8)


def render(path, size=64):
    scene, cameras = load_quietly(path)
    return mr.render(scene, cameras[0], size, size).color


def test_instanced_render_equals_one_node_per_instance(tmp_path):
    # The oracle: the same instances as child nodes (same TRS numbers) of a node with NODE's transform.
    spread = np.float32([[-0.5, 0.5, 0], [0.5, 0.5, 0], [-0.5, -0.5, 0], [0.5, -0.4, 0.1]])  # one per quadrant
    got = render(write_instanced(tmp_path / "instanced.gltf",
                                 {"TRANSLATION": spread, "ROTATION": ROTATION, "SCALE": SCALE}))
    children = [{"mesh": 0, "translation": spread[i].tolist(), "rotation": ROTATION[i].tolist(),
                 "scale": SCALE[i].tolist()} for i in range(len(spread))]
    parent = dict(NODE, children=list(range(1, len(children) + 1)))
    want = render(write_doc(tmp_path / "nodes.gltf", [parent, *children], [0]))
    assert np.array_equal(got, want)
    # A quad in each quadrant of the image.
    covered = got[..., 3] > 0
    for quadrant in (covered[:32, :32], covered[:32, 32:], covered[32:, :32], covered[32:, 32:]):
        assert quadrant.sum() > 0.2 * 0.2 * 0.5 * 32 * 32


@pytest.mark.parametrize("dtype, scale", [(np.int16, 32767), (np.int8, 127)], ids=["short", "byte"])
def test_normalized_integer_rotations(tmp_path, dtype, scale):
    quantized = np.round(ROTATION * scale).astype(dtype)
    values = {"TRANSLATION": TRANSLATION, "ROTATION": quantized}
    scene, _ = load_quietly(write_instanced(tmp_path / "quantized.gltf", values))
    node = trs(NODE["translation"], scale=NODE["scale"])
    assert len(scene.draws) == len(TRANSLATION)
    for i, draw in enumerate(scene.draws):
        rotation = np.maximum(quantized[i] / scale, -1.0)  # glTF's normalized signed integers
        np.testing.assert_allclose(draw.model, node @ trs(TRANSLATION[i], rotation), rtol=0, atol=1e-12)
    # Close to the float rotations they quantize (a quarter turn is still one).
    want = np.diag([1.2, 0.8, 1]) @ quaternion_matrix(*ROTATION[1])[:3, :3]
    np.testing.assert_allclose(scene.draws[1].model[:3, :3], want, atol=2.0 / scale)


def test_primitives_draw_each_with_all_instances_sharing_one_mesh(tmp_path):
    path = write_instanced(tmp_path / "two.gltf", {"TRANSLATION": TRANSLATION[:3]})
    doc = json.loads(path.read_text())
    prim = doc["meshes"][0]["primitives"][0]
    doc["materials"] = [{"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1]}}]
    doc["meshes"][0]["primitives"].append(dict(prim, material=0))
    path.write_text(json.dumps(doc))
    scene, _ = load_quietly(path)
    assert len(scene.draws) == 6
    assert [d.color for d in scene.draws] == [(1.0, 1.0, 1.0, 1.0)] * 3 + [(0.5, 0.5, 0.5, 1.0)] * 3
    node = trs(NODE["translation"], scale=NODE["scale"])
    for k, draw in enumerate(scene.draws):
        np.testing.assert_allclose(draw.model, node @ trs(TRANSLATION[k % 3]), rtol=0, atol=1e-12)


def test_children_of_an_instanced_node_are_drawn_once(tmp_path):
    path = write_instanced(tmp_path / "child.gltf", {"TRANSLATION": TRANSLATION})
    doc = json.loads(path.read_text())
    doc["nodes"][0]["children"] = [2]
    doc["nodes"].append({"mesh": 0, "translation": [0, 0.5, 0]})
    path.write_text(json.dumps(doc))
    scene, _ = load_quietly(path)
    assert len(scene.draws) == 5
    np.testing.assert_allclose(scene.draws[4].model, trs(NODE["translation"], scale=NODE["scale"]) @ trs((0, 0.5, 0)),
                               rtol=0, atol=1e-12)


def test_extension_on_a_node_without_a_mesh_is_ignored(tmp_path):
    path = write_instanced(tmp_path / "meshless.gltf", {"TRANSLATION": TRANSLATION})
    doc = json.loads(path.read_text())
    del doc["nodes"][0]["mesh"]
    doc["nodes"].append({"mesh": 0})
    doc["scenes"][0]["nodes"].append(len(doc["nodes"]) - 1)
    path.write_text(json.dumps(doc))
    scene, _ = load_quietly(path)
    assert len(scene.draws) == 1
    np.testing.assert_array_equal(scene.draws[0].model, np.eye(4))


def test_extension_without_transform_attributes_draws_the_node_once_with_a_warning(tmp_path):
    path = write_instanced(tmp_path / "ids.gltf", {"_ID": np.float32([[0, 0, 0], [1, 1, 1]])})
    scene, texts = load_warning_texts(path)
    assert len(scene.draws) == 1
    assert [t for t in texts if "EXT_mesh_gpu_instancing has no TRANSLATION, ROTATION or SCALE" in t]


def test_custom_attributes_are_not_read(tmp_path):
    # An _ID accessor of another count and type does not matter.
    values = {"TRANSLATION": TRANSLATION, "_ID": np.float32([[7, 7, 7]])}
    scene, _ = load_quietly(write_instanced(tmp_path / "custom.gltf", values, _ID={"type": "VEC2"}))
    assert len(scene.draws) == len(TRANSLATION)


HUGE = 10**9
BAD_INSTANCES = {
    # name: (values, accessor edits, the error class, the problem the message names)
    "unequal_counts": ({"TRANSLATION": TRANSLATION, "SCALE": SCALE[:3]}, {}, OSError,
                       r"EXT_mesh_gpu_instancing: SCALE \(accessor 4\) has 3 elements, TRANSLATION \(accessor 3\) 4; "
                       r"every instance attribute must have the same count"),
    "nan_translation": ({"TRANSLATION": np.where(np.arange(12).reshape(4, 3) == 7, np.nan, TRANSLATION)
                         .astype(np.float32)}, {}, OSError,
                        r"EXT_mesh_gpu_instancing TRANSLATION \(accessor 3\): TRANSLATION of instance 2 is not finite"),
    "inf_scale": ({"SCALE": np.where(np.arange(12).reshape(4, 3) == 0, np.inf, SCALE).astype(np.float32)}, {},
                  OSError, r"EXT_mesh_gpu_instancing SCALE \(accessor 3\): SCALE of instance 0 is not finite"),
    "zero_rotation": ({"ROTATION": np.zeros((4, 4), np.float32)}, {}, OSError,
                      r"EXT_mesh_gpu_instancing instance 0: ROTATION is not a valid quaternion"),
    "absurd_count": ({"TRANSLATION": TRANSLATION}, {"TRANSLATION": {"count": HUGE}}, mr.MemoryLimitError,
                     rf"EXT_mesh_gpu_instancing TRANSLATION \(accessor 3\): {HUGE} instances of 2 triangle\(s\) "
                     r"needs .*the memory limit"),
    "beyond_32_bits": ({"ROTATION": ROTATION}, {"ROTATION": {"count": 2**33}}, OSError,
                       rf"EXT_mesh_gpu_instancing ROTATION \(accessor 3\): absurd instance count {2**33}"),
    "outside_buffer": ({"TRANSLATION": TRANSLATION}, {"TRANSLATION": {"count": 5}}, OSError,
                       r"EXT_mesh_gpu_instancing TRANSLATION \(accessor 3\): 5 elements need 60 bytes"),
    "translation_vec4": ({"TRANSLATION": ROTATION}, {}, OSError,
                         r"EXT_mesh_gpu_instancing TRANSLATION \(accessor 3\): TRANSLATION must be VEC3"),
    "unnormalized_rotation": ({"ROTATION": np.int16(ROTATION * 32767)}, {"ROTATION": {"normalized": False}},
                              OSError, r"EXT_mesh_gpu_instancing ROTATION \(accessor 3\): ROTATION must be float or "
                                       r"normalized byte/short, got component type 5122"),
    "missing_accessor": ({"SCALE": SCALE}, {"SCALE": {}}, OSError, None),
}


@pytest.mark.parametrize("case", sorted(BAD_INSTANCES))
def test_bad_instances_are_errors_naming_the_node_and_accessor(tmp_path, case):
    values, edits, error, problem = BAD_INSTANCES[case]
    path = write_instanced(tmp_path / "bad.gltf", values, **edits)
    if case == "missing_accessor":
        doc = json.loads(path.read_text())
        doc["nodes"][0]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]["SCALE"] = 9
        path.write_text(json.dumps(doc))
        problem = r"EXT_mesh_gpu_instancing: SCALE: accessor 9 does not exist \(the file has 4\)"
    with pytest.raises(error, match=r"bad\.gltf: node 0 \('trees'\): " + problem):
        mr.load_scene(path)


def test_instance_whose_world_matrix_overflows_is_an_error(tmp_path):
    path = write_instanced(tmp_path / "overflow.gltf", {"SCALE": SCALE * 1e30}, node={"scale": [1e300, 1, 1]})
    with pytest.raises(OSError, match=r"overflow\.gltf: node 0 \('trees'\): EXT_mesh_gpu_instancing instance 0: "
                                      r"its world matrix is not finite"):
        mr.load_scene(path)


def test_absurd_instance_count_is_refused_even_without_triangles(tmp_path):
    # A mesh of points only draws nothing, but a billion instances would still be a billion matrices.
    path = write_instanced(tmp_path / "points.gltf", {"TRANSLATION": TRANSLATION}, TRANSLATION={"count": HUGE})
    doc = json.loads(path.read_text())
    doc["meshes"][0]["primitives"][0]["mode"] = 0
    path.write_text(json.dumps(doc))
    with pytest.raises(mr.MemoryLimitError, match=rf"points\.gltf: node 0 \('trees'\): EXT_mesh_gpu_instancing "
                                                  rf"TRANSLATION \(accessor 3\): {HUGE} instances of 0 triangle"):
        mr.load_scene(path)
