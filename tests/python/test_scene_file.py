"""mipraster.load_scene and `mipraster render SCENE`: OBJ and glTF files written by the tests,
untextured and textured (uvs, base colour textures, samplers, missing textures)."""
import base64
import json
import math
import os
import re
import struct
import subprocess
import warnings

import numpy as np
import pytest
from PIL import Image

import mipraster as mr
from test_cli import EXE


def write_gltf(path, color=(1.0, 0.0, 0.0, 1.0)):
    """A small triangle around the origin (z = 0) and a perspective camera at (0, 0, 5) facing it."""
    positions = [-0.2, -0.2, 0.0, 0.2, -0.2, 0.0, 0.0, 0.2, 0.0]
    buf = struct.pack("<9f", *positions) + struct.pack("<3H", 0, 1, 2) + b"\0\0"
    doc = {
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 0, 5], "name": "cam"}],
        "cameras": [{"type": "perspective", "name": "main", "perspective": {"yfov": 0.5, "znear": 0.1}}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": list(color)}, "doubleSided": True}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
            {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"},
        ],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                        {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
        "buffers": [{"byteLength": len(buf),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(buf).decode()}],
    }
    path.write_text(json.dumps(doc))
    return path


def test_gltf_round_trip(tmp_path):
    scene, cameras = mr.load_scene(write_gltf(tmp_path / "tri.gltf", color=(0.5, 0.25, 1.0, 1.0)))
    assert len(scene.draws) == 1 and len(cameras) == 1
    d = scene.draws[0]
    np.testing.assert_array_equal(d.mesh.positions[2], np.float32([0.0, 0.2, 0.0]))
    np.testing.assert_array_equal(d.mesh.triangles, [[0, 1, 2]])
    assert d.color == (0.5, 0.25, 1.0, 1.0)
    assert d.cull == "none" and d.blend == "replace"
    view, projection = cameras[0].matrices(64, 32)
    np.testing.assert_allclose(view[:3, 3], [0, 0, -5])
    assert projection[1, 1] == pytest.approx(1 / math.tan(0.25))
    assert projection[0, 0] == pytest.approx(1 / math.tan(0.25) / 2)  # the render's aspect (the file gives none)
    assert "main" in repr(cameras[0])


def test_loaded_camera_puts_the_target_on_the_image_centre(tmp_path):
    scene, cameras = mr.load_scene(write_gltf(tmp_path / "tri.gltf"))
    np.testing.assert_allclose(cameras[0].project([0, 0, 0], 33, 33)[:2], [16.5, 16.5])
    result = mr.render(scene, cameras[0], 33, 33)
    np.testing.assert_allclose(result.color[16, 16], [1, 0, 0, 1])
    np.testing.assert_array_equal(result.color[0, 0], [0, 0, 0, 0])


def test_obj_round_trip(tmp_path):
    (tmp_path / "m.mtl").write_text("newmtl green\nKd 0 0.5 0\n")
    path = tmp_path / "m.obj"
    path.write_text("mtllib m.mtl\nv 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nvt 0 0\nusemtl green\nf 1 2 3\n")
    scene, cameras = mr.load_scene(str(path))
    assert cameras == []
    (d,) = scene.draws
    assert d.color == (0.0, 0.5, 0.0, 1.0)
    np.testing.assert_array_equal(d.mesh.positions, [[0, 0, 0], [1, 0, 0], [0, 1, 0]])
    np.testing.assert_array_equal(d.mesh.colors[1], [0, 1, 0, 1])


def test_load_errors_name_the_file(tmp_path):
    with pytest.raises(FileNotFoundError):
        mr.load_scene(tmp_path / "missing.gltf")
    bad = tmp_path / "bad.gltf"
    bad.write_text('{"asset": {"version": "2.0"}, "meshes": [')
    with pytest.raises(OSError, match="bad.gltf"):
        mr.load_scene(bad)
    other = tmp_path / "scene.fbx"
    other.write_text("x")
    with pytest.raises(ValueError, match=r"\.obj, \.gltf, \.glb"):
        mr.load_scene(other)


def run(*args):
    return subprocess.run([EXE, *args], capture_output=True, text=True, timeout=300)


def test_cli_renders_a_scene_file_with_its_camera(tmp_path):
    scene = write_gltf(tmp_path / "scene.gltf")
    out = tmp_path / "out.png"
    r = run("render", str(scene), "-o", str(out), "--camera", "0", "--size", "33x33", "--quiet")
    assert r.returncode == 0, r.stderr
    img = np.asarray(Image.open(out))
    np.testing.assert_array_equal(img[16, 16], [255, 0, 0, 255])
    assert abs(int(img[0, 0, 0]) - int(img[0, 0, 1])) <= 1 and img[0, 0, 3] == 255  # neutral grey clear


def test_cli_frames_an_obj_without_cameras(tmp_path):
    path = tmp_path / "t.obj"
    path.write_text("v 10 0 0\nv 12 0 0\nv 10 2 0\nf 1 2 3\n")
    out = tmp_path / "obj.png"
    r = run("render", str(path), "-o", str(out), "--size", "32x32", "--quiet")
    assert r.returncode == 0, r.stderr
    img = np.asarray(Image.open(out))
    assert (img[..., :3] == 255).all(axis=-1).any()  # the white triangle is in view


def test_cli_errors_name_the_file_or_camera(tmp_path):
    missing = tmp_path / "missing.gltf"
    r = run("render", str(missing), "-o", str(tmp_path / "x.png"))
    assert r.returncode != 0 and str(missing) in r.stderr
    scene = write_gltf(tmp_path / "scene.gltf")
    r = run("render", str(scene), "-o", str(tmp_path / "x.png"), "--camera", "3")
    assert r.returncode != 0
    assert "--camera 3" in r.stderr and "1 camera" in r.stderr


# --- textures -------------------------------------------------------------------------------

# The 2x2 test texture, linear RGBA: red, green / blue, white (every value exact in sRGB8).
TEXELS = np.float32([[[1, 0, 0, 1], [0, 1, 0, 1]], [[0, 0, 1, 1], [1, 1, 1, 1]]])


def write_texture(path):
    mr.write_image(path, TEXELS)  # sRGB 8-bit PNG
    return path


def write_textured_gltf(path, image, sampler=None):
    """A quad filling [-1, 1]^2 at z = 0 with uv (0, 0) at its top-left corner (x = -1, y = 1), the
    texture `image` (a dict: {"uri": ...}), and an orthographic camera at z = 5 that sees exactly it."""
    positions = [-1, 1, 0, 1, 1, 0, 1, -1, 0, -1, -1, 0]
    uvs = [0, 0, 1, 0, 1, 1, 0, 1]
    buf = struct.pack("<12f", *positions) + struct.pack("<8f", *uvs) + struct.pack("<6H", 0, 2, 1, 0, 3, 2)
    doc = {
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 0, 5]}],
        "cameras": [{"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 10}}],
        "materials": [{"name": "checker", "doubleSided": True,
                       "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
        "textures": [{"source": 0, **({} if sampler is None else {"sampler": 0})}],
        "samplers": [] if sampler is None else [sampler],
        "images": [image],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "material": 0}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"},
        ],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48},
                        {"buffer": 0, "byteOffset": 48, "byteLength": 32},
                        {"buffer": 0, "byteOffset": 80, "byteLength": 12}],
        "buffers": [{"byteLength": len(buf) + 4,
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(buf + b"\0" * 4).decode()}],
    }
    path.write_text(json.dumps(doc))
    return path


@pytest.mark.parametrize("uri", [".", "sub", "/dev/zero", "missing.bin"])
def test_gltf_buffer_that_is_not_a_readable_file_is_an_error_naming_it(tmp_path, uri):
    # A directory was opened and its "size" allocated: std::bad_alloc.
    (tmp_path / "sub").mkdir()
    path = write_textured_gltf(tmp_path / "quad.gltf", {"uri": "missing.png"})
    doc = json.loads(path.read_text())
    doc["buffers"][0]["uri"] = uri
    path.write_text(json.dumps(doc))
    with pytest.raises(OSError, match=r"quad\.gltf: cannot read glTF: File not found : ") as e:
        mr.load_scene(path)
    assert f"File not found : {uri}:" in str(e.value)


@pytest.mark.parametrize("nodes, message", [
    ([{"children": [1, 1]}, {"mesh": 0}], "node 1 is listed as a child twice by node 0"),
    ([{"children": [2]}, {"children": [2]}, {"mesh": 0}], "node 2 is listed as a child by both node 0 and node 1"),
    # each node twice the child of the one before: 2^40 paths to the mesh, a draw each (the load ran
    # for minutes and allocated gigabytes before failing)
    ([{"children": [i + 1, i + 1]} for i in range(40)] + [{"mesh": 0}], "node 1 is listed as a child twice by node 0"),
])
def test_gltf_node_with_more_than_one_parent_is_an_error_naming_it(tmp_path, nodes, message):
    path = write_gltf(tmp_path / "dag.gltf")
    doc = json.loads(path.read_text())
    doc["nodes"], doc["scenes"] = nodes, [{"nodes": [0, 1] if "both" in message else [0]}]
    path.write_text(json.dumps(doc))
    with pytest.raises(OSError, match=rf"dag\.gltf: {message} \(a glTF node has at most one parent\)"):
        mr.load_scene(path)


@pytest.mark.parametrize("depth, message", [(1024, None), (1025, "lies more than 1024 levels below its root")])
def test_gltf_node_chain_deeper_than_the_limit_is_named_as_such(tmp_path, depth, message):
    # (the limit's error called the chain a cycle)
    path = write_gltf(tmp_path / "chain.gltf")
    doc = json.loads(path.read_text())
    doc["nodes"] = [{"children": [i + 1]} for i in range(depth)] + [{"mesh": 0}]
    doc["scenes"] = [{"nodes": [0]}]
    path.write_text(json.dumps(doc))
    if message is None:
        scene, _ = mr.load_scene(path)
        assert len(scene.draws) == 1
        return
    with pytest.raises(OSError, match=rf"chain\.gltf: node {depth} {message}") as e:
        mr.load_scene(path)
    assert "cycle" not in str(e.value)


@pytest.mark.parametrize("asset, message", [
    ({"version": "2.1"}, None),
    ({"version": "2.0", "minVersion": "2.0"}, None),
    ({"version": "1.0"}, r"glTF version '1\.0' is not supported \(this loader reads glTF 2\.x\)"),
    ({"version": "3.0"}, r"glTF version '3\.0' is not supported"),
    ({"version": "2.1", "minVersion": "2.1"}, r"the file needs glTF 2\.1 \(asset\.minVersion\)"),
])
def test_gltf_of_another_version_is_an_error_naming_it(tmp_path, asset, message):
    # (a 1.0 or 3.0 file was read as 2.0; the spec has loaders refuse another major version, or a
    # minVersion above theirs)
    path = write_gltf(tmp_path / "versioned.gltf")
    doc = json.loads(path.read_text())
    doc["asset"] = asset
    path.write_text(json.dumps(doc))
    if message is None:
        assert len(mr.load_scene(path)[0].draws) == 1
        return
    with pytest.raises(OSError, match=r"versioned\.gltf: " + message):
        mr.load_scene(path)


def glb_of(doc, version=2):
    """A .glb file of `doc` (its buffer stays a data URI): the header and one JSON chunk."""
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    return struct.pack("<4sIII4s", b"glTF", version, 20 + len(text), len(text), b"JSON") + text


@pytest.mark.parametrize("version, message", [
    (2, None),
    (1, r"GLB version 1 is not supported \(glTF 2\.0 needs GLB version 2\)"),
    (3, r"GLB version 3 is not supported"),
])
def test_glb_of_another_version_is_an_error_naming_it(tmp_path, version, message):
    # (a version 1 header was read as version 2)
    doc = json.loads(write_gltf(tmp_path / "tri.gltf").read_text())
    path = tmp_path / "versioned.glb"
    path.write_bytes(glb_of(doc, version))
    if message is None:
        assert len(mr.load_scene(path)[0].draws) == 1
        return
    with pytest.raises(OSError, match=r"versioned\.glb: " + message):
        mr.load_scene(path)


@pytest.mark.parametrize("indices", [-5, -2])
@pytest.mark.parametrize("suffix", [".gltf", ".glb"])
def test_gltf_indices_that_name_no_accessor_are_an_error_naming_the_primitive(tmp_path, indices, suffix):
    # tinygltf does not check negative indices (those beyond the last accessor it names itself): the
    # primitive was drawn unindexed. (A written -1 or 1.5 it reads as "no indices", as if the key
    # were missing: that one it cannot tell.)
    doc = json.loads(write_gltf(tmp_path / "tri.gltf").read_text())
    doc["meshes"][0]["primitives"][0]["indices"] = indices
    path = tmp_path / f"idx{suffix}"
    if suffix == ".glb":
        path.write_bytes(glb_of(doc))
    else:
        path.write_text(json.dumps(doc))
    with pytest.raises(OSError, match=rf"idx{re.escape(suffix)}: meshes\[0\]\.primitives\[0\] indices: "
                                      rf"accessor {re.escape(str(indices))} does not exist \(the file has 2\)"):
        mr.load_scene(path)


def test_gltf_primitive_without_indices_still_loads_unindexed(tmp_path):
    path = write_gltf(tmp_path / "tri.gltf")
    doc = json.loads(path.read_text())
    del doc["meshes"][0]["primitives"][0]["indices"]
    path.write_text(json.dumps(doc))
    scene, _ = mr.load_scene(path)
    np.testing.assert_array_equal(scene.draws[0].mesh.triangles, [[0, 1, 2]])


@pytest.mark.parametrize("roots, message", [
    ([0, 1], None),
    ([0, 1, 2], r"node 2 is listed in scenes\[0\]\.nodes and as a child of node 0 \(a scene lists only root nodes\)"),
    ([0, 1, 0], r"node 0 is listed twice in scenes\[0\]\.nodes"),
])
def test_gltf_scene_node_that_is_no_root_is_an_error_naming_it(tmp_path, roots, message):
    # (such a node was drawn once as a root and once as its parent's child)
    path = write_gltf(tmp_path / "roots.gltf")
    doc = json.loads(path.read_text())
    doc["nodes"] = [{"mesh": 0, "children": [2]}, doc["nodes"][1], {"mesh": 0, "translation": [0.5, 0, 0]}]
    doc["scenes"] = [{"nodes": roots}]
    path.write_text(json.dumps(doc))
    if message is None:
        assert len(mr.load_scene(path)[0].draws) == 2
        return
    with pytest.raises(OSError, match=r"roots\.gltf: " + message):
        mr.load_scene(path)


def test_gltf_unknown_alpha_mode_warns_naming_the_material_and_draws_opaque(tmp_path):
    # (it was drawn OPAQUE without a word, like the bad wrapS the loader warns about)
    path = write_gltf(tmp_path / "alpha.gltf", color=(1.0, 0.0, 0.0, 0.5))
    doc = json.loads(path.read_text())
    doc["materials"][0]["alphaMode"] = "WEIRD"
    path.write_text(json.dumps(doc))
    scene, messages = load_warning_texts(path)
    assert messages == [f"{path}: material materials[0]: alphaMode 'WEIRD' is not OPAQUE, MASK or BLEND; using OPAQUE"]
    (d,) = scene.draws
    assert d.blend == "replace" and d.alpha_cutoff is None and d.color == (1.0, 0.0, 0.0, 1.0)


@pytest.mark.parametrize("value, written", [(1e30, "1e+30"), (-5.0, "-5"), (1.0, None)])
def test_gltf_color_0_outside_0_1_is_clamped_with_a_warning_naming_the_primitive(tmp_path, value, written):
    # (1e30 was drawn as it was, far beyond white, and -5 as a negative colour)
    path = write_gltf(tmp_path / "col.gltf")
    doc = json.loads(path.read_text())
    buf = base64.b64decode(doc["buffers"][0]["uri"].split(",")[1])
    colours = struct.pack("<12f", value, 0, 0, 1, 0, 1, 0, 1, 0, 0, 1, 1)
    doc["buffers"] = [{"byteLength": len(buf) + 48,
                       "uri": "data:application/octet-stream;base64," + base64.b64encode(buf + colours).decode()}]
    doc["bufferViews"].append({"buffer": 0, "byteOffset": len(buf), "byteLength": 48})
    doc["accessors"].append({"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC4"})
    doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = 2
    path.write_text(json.dumps(doc))
    scene, messages = load_warning_texts(path)
    colors = scene.draws[0].mesh.colors
    np.testing.assert_array_equal(colors[1:], [[0, 1, 0, 1], [0, 0, 1, 1]])
    np.testing.assert_array_equal(colors[0], [min(max(value, 0), 1), 0, 0, 1])
    if written is None:
        assert messages == []
        return
    assert messages == [f"{path}: meshes[0].primitives[0] COLOR_0 (accessor 2): 1 value(s) outside [0, 1], the "
                        f"spec's range (vertex 0 is ({written}, 0, 0, 1)); clamped to [0, 1]"]


@pytest.mark.parametrize("factor", [[1e39, 0, 0, 1], [1e30, 1, 1, 1e30]])
def test_gltf_base_color_beyond_float_is_an_error_naming_the_material(tmp_path, factor):
    # a component past float's range, or (BLEND) a colour times alpha past it
    path = write_gltf(tmp_path / "big.gltf")
    doc = json.loads(path.read_text())
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = factor
    if factor[3] != 1:
        doc["materials"][0]["alphaMode"] = "BLEND"
    path.write_text(json.dumps(doc))
    with pytest.raises(OSError, match=r"big\.gltf: material .*: baseColorFactor is beyond float's range"):
        mr.load_scene(path)


NEAREST_CLAMP = {"magFilter": 9728, "minFilter": 9728, "wrapS": 33071, "wrapT": 33648}


def quadrant_colors(color):
    """The colours at the centres of the four quadrants of a rendered image: TL, TR, BL, BR."""
    h, w = color.shape[:2]
    return [color[h // 4, w // 4], color[h // 4, 3 * w // 4], color[3 * h // 4, w // 4], color[3 * h // 4, 3 * w // 4]]


def test_gltf_texture_renders_with_its_sampler(tmp_path):
    write_texture(tmp_path / "checker.png")
    path = write_textured_gltf(tmp_path / "tex.gltf", {"uri": "checker.png"}, NEAREST_CLAMP)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a complete file loads without warnings
        scene, cameras = mr.load_scene(path)
    (d,) = scene.draws
    np.testing.assert_array_equal(d.mesh.uvs, [[0, 0], [1, 0], [1, 1], [0, 1]])
    assert d.texture is not None and (d.texture.width, d.texture.height) == (2, 2)
    assert d.texture.name == str(tmp_path / "checker.png")
    np.testing.assert_allclose(d.texture.level(0), TEXELS, atol=1e-6)  # decoded back to linear
    s = d.sampler
    # NEAREST / NEAREST (no mip levels) is the "nearest" preset; the wraps are per axis.
    assert s == mr.Sampler(filter="nearest", wrap=("clamp", "mirror"))
    assert not s.uses_mip_levels
    result = mr.render(scene, cameras[0], 32, 32)
    got = quadrant_colors(result.color)
    for q, expected in enumerate([TEXELS[0, 0], TEXELS[0, 1], TEXELS[1, 0], TEXELS[1, 1]]):
        np.testing.assert_allclose(got[q], expected, atol=1e-6, err_msg=f"quadrant {q}")


def test_gltf_embedded_texture_and_default_sampler(tmp_path):
    png = write_texture(tmp_path / "src.png").read_bytes()
    image = {"uri": "data:image/png;base64," + base64.b64encode(png).decode()}
    scene, cameras = mr.load_scene(write_textured_gltf(tmp_path / "embedded.gltf", image))
    (d,) = scene.draws
    np.testing.assert_allclose(d.texture.level(0), TEXELS, atol=1e-6)
    s = d.sampler  # no glTF sampler: the library default (trilinear, repeat)
    assert s == mr.Sampler()
    color = mr.render(scene, cameras[0], 64, 64).color
    # Bilinear magnification: the quadrant centres are close to the texels' colours.
    got = quadrant_colors(color)
    for q, expected in enumerate([TEXELS[0, 0], TEXELS[0, 1], TEXELS[1, 0], TEXELS[1, 1]]):
        assert np.abs(got[q] - expected).max() < 0.05, (q, got[q])


def write_webp(path, texels):
    """`texels` (linear, opaque) as a lossless WebP file: the sRGB bytes a PNG of them holds."""
    Image.fromarray(mr.to_srgb8(texels)).save(path, "WEBP", lossless=True)
    return path


@pytest.mark.parametrize("fallback", [False, True])
def test_gltf_webp_texture_of_ext_texture_webp(tmp_path, fallback):
    # EXT_texture_webp: the texture's WebP source is drawn, not its PNG fallback (which holds other
    # texels); a file without a fallback requires the extension, and loads.
    write_webp(tmp_path / "checker.webp", TEXELS)
    mr.write_image(tmp_path / "fallback.png", TEXELS[::-1])
    path = write_textured_gltf(tmp_path / "webp.gltf", {"uri": "fallback.png"}, NEAREST_CLAMP)
    doc = json.loads(path.read_text())
    doc["images"].append({"uri": "checker.webp", "mimeType": "image/webp"})
    doc["textures"][0]["extensions"] = {"EXT_texture_webp": {"source": 1}}
    doc["extensionsUsed"] = ["EXT_texture_webp"]
    if not fallback:
        del doc["textures"][0]["source"]
        doc["extensionsRequired"] = ["EXT_texture_webp"]
    path.write_text(json.dumps(doc))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        scene, cameras = mr.load_scene(path)
    (d,) = scene.draws
    assert d.texture.name == str(tmp_path / "checker.webp")
    np.testing.assert_allclose(d.texture.level(0), TEXELS, atol=1e-6)
    got = quadrant_colors(mr.render(scene, cameras[0], 32, 32).color)
    for q, expected in enumerate([TEXELS[0, 0], TEXELS[0, 1], TEXELS[1, 0], TEXELS[1, 1]]):
        np.testing.assert_allclose(got[q], expected, atol=1e-6, err_msg=f"quadrant {q}")


@pytest.mark.parametrize("source, words", [(5, "EXT_texture_webp source image 5 does not exist"),
                                           ("one", "EXT_texture_webp source is not an image index"),
                                           (-1, "EXT_texture_webp source image -1 is not an image index")])
def test_gltf_bad_ext_texture_webp_source_is_an_error_naming_it(tmp_path, source, words):
    path = write_textured_gltf(tmp_path / "bad.gltf", {"uri": "fallback.png"})
    doc = json.loads(path.read_text())
    doc["textures"][0]["extensions"] = {"EXT_texture_webp": {"source": source}}
    path.write_text(json.dumps(doc))
    with pytest.raises(OSError, match=r"bad\.gltf: textures\[0\]: " + re.escape(words)):
        mr.load_scene(path)


def test_gltf_data_uri_of_any_image_type_is_decoded(tmp_path):
    # tinygltf decodes PNG, JPEG, BMP and GIF data URIs; the loader decodes the others (here WebP)
    # itself. Unpadded base64 too.
    webp = write_webp(tmp_path / "src.webp", TEXELS).read_bytes()
    for padding in (True, False):
        text = base64.b64encode(webp).decode()
        image = {"uri": "data:image/webp;base64," + (text if padding else text.rstrip("="))}
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            scene, _ = mr.load_scene(write_textured_gltf(tmp_path / "embedded.gltf", image))
        np.testing.assert_allclose(scene.draws[0].texture.level(0), TEXELS, atol=1e-6)


def test_obj_texture_flips_v(tmp_path):
    write_texture(tmp_path / "checker.png")
    (tmp_path / "m.mtl").write_text("newmtl tex\nKd 1 1 1\nmap_Kd checker.png\n")
    path = tmp_path / "quad.obj"
    # OBJ's vt (0, 0) is the image's bottom-left corner: put it at the quad's bottom-left.
    path.write_text("mtllib m.mtl\n"
                    "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n"
                    "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n"
                    "usemtl tex\nf 1/1/1 2/2/1 3/3/1 4/4/1\n")
    scene, cameras = mr.load_scene(path)
    assert cameras == []
    (d,) = scene.draws
    assert d.texture is not None and d.sampler == mr.Sampler()
    np.testing.assert_array_equal(d.mesh.uvs[d.mesh.positions[:, 0].argmin()], [0, 1])  # a left corner ...
    np.testing.assert_array_equal(d.mesh.normals, np.tile([0, 0, 1], (4, 1)))
    camera = mr.Camera.orthographic((0, 0, 5), (0, 0, 0), height=2.0, near=0.1, far=10)
    got = quadrant_colors(mr.render(scene, camera, 64, 64).color)
    # Upright: the image's top row (red, green) is at the top of the render.
    for q, expected in enumerate([TEXELS[0, 0], TEXELS[0, 1], TEXELS[1, 0], TEXELS[1, 1]]):
        assert np.abs(got[q] - expected).max() < 0.05, (q, got[q])


def test_missing_texture_warns_and_renders_the_error_texture(tmp_path):
    path = write_textured_gltf(tmp_path / "missing.gltf", {"uri": "nowhere.png"}, NEAREST_CLAMP)
    with pytest.warns(UserWarning, match=r"material 'checker'.*nowhere\.png"):
        scene, cameras = mr.load_scene(path)
    (d,) = scene.draws
    assert d.texture.name == "error texture" and (d.texture.width, d.texture.height) == (8, 8)
    color = mr.render(scene, cameras[0], 16, 16).color  # one texel per 2x2 pixels, nearest
    np.testing.assert_allclose(color[0, 0], [1, 0, 1, 1], atol=1e-6)  # magenta
    np.testing.assert_allclose(color[0, 2], [0, 0, 0, 1], atol=1e-6)  # black


def test_hostile_texture_reference_is_an_error_naming_the_file(tmp_path):
    write_texture(tmp_path / "checker.png")
    path = write_textured_gltf(tmp_path / "bad_sampler.gltf", {"uri": "checker.png"}, NEAREST_CLAMP)
    doc = json.loads(path.read_text())
    doc["textures"][0]["sampler"] = 4
    path.write_text(json.dumps(doc))
    with pytest.raises(OSError, match=r"bad_sampler\.gltf.*sampler 4 does not exist"):
        mr.load_scene(path)


@pytest.mark.parametrize("text", ["", "v 0 0 0\nv 1 0 0\n"])
def test_file_without_triangles_warns(tmp_path, text):
    path = tmp_path / "nothing.obj"
    path.write_text(text)
    with pytest.warns(UserWarning, match="the file holds no triangles"):
        scene, _ = mr.load_scene(path)
    assert sum(len(d.mesh.triangles) for d in scene.draws) == 0


def test_obj_coordinate_that_is_not_a_number_is_an_error(tmp_path):
    path = tmp_path / "nan.obj"
    path.write_text("v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n")
    with pytest.raises(OSError, match=r"line 2 \('v nan 0 0'\): 'nan' is not a finite number"):
        mr.load_scene(path)
    path.write_text("v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n")  # finite, but not as a float
    with pytest.raises(OSError, match=r"line 2 \('v 1e39 0 0'\): '1e39' is beyond float's range"):
        mr.load_scene(path)


@pytest.mark.parametrize("corner", ["4294967297", "99999999999999999999", "2147483648", "1/4294967297", "1//x"])
def test_obj_face_index_beyond_an_int_is_an_error(tmp_path, corner):
    # tinyobjloader wrapped such indices around: 'f 1 2 4294967297' loaded as the triangle 1 2 1.
    path = tmp_path / "index.obj"
    path.write_text(f"v -1 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1 2 {corner}\n")
    part = corner.split("/")[-1]
    with pytest.raises(OSError, match=rf"line 5 \('f 1 2 {corner}'\): '{part}' is not an index"):
        mr.load_scene(path)
    # The largest index that fits is only out of range, and relative indices still load.
    path.write_text("v -1 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2147483647\n")
    with pytest.raises(OSError, match="vertex index 2147483647 out of range"):
        mr.load_scene(path)
    path.write_text("v -1 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n")
    scene, _ = mr.load_scene(path)
    assert scene.draws[0].mesh.triangles.tolist() == [[0, 1, 2]]


def test_scene_file_renders_are_deterministic(tmp_path):
    # A textured glTF seen at a grazing angle (minification, edges): the same bits on every run,
    # for any thread count, through Python and through the CLI (with anisotropic filtering).
    write_texture(tmp_path / "checker.png")
    path = write_textured_gltf(tmp_path / "plane.gltf", {"uri": "checker.png"})
    scene, _ = mr.load_scene(path)
    camera = mr.Camera.look_at((0.3, -2.5, 0.6), (0, 0.5, 0), up=(0, 0, 1), fov_y=50)
    renders = [mr.render(scene, camera, 96, 64, spp=4, aa=aa, threads=t).color
               for aa in ("msaa", "ssaa") for t in (1, 2, 4, 1)]
    for group in (renders[:4], renders[4:]):
        for r in group[1:]:
            assert np.array_equal(r, group[0])
    assert len(np.unique(renders[0].reshape(-1, 4), axis=0)) > 20  # a real picture, not a blank
    outs = []
    for t in ("1", "2"):
        out = tmp_path / f"cli_{t}.png"
        r = run("render", str(path), "-o", str(out), "--size", "64x48", "--threads", t, "--filter", "anisotropic")
        assert r.returncode == 0, r.stderr
        outs.append(out.read_bytes())
    assert outs[0] == outs[1]


# --- glTF as found in the wild: strips and fans, sparse accessors, texCoord sets, texture transforms,
# required extensions. Each file is compared with an independent oracle: the same surface written in
# the plain form the loader already read (TRIANGLES, dense accessors, TEXCOORD_0, uvs transformed here).

def data_uri(data):
    return "data:application/octet-stream;base64," + base64.b64encode(data).decode()


def write_mesh_gltf(path, chunks, accessors, primitives, materials=None, extra=None, camera_z=5.0, meshes=None,
                    nodes=None):
    """A glTF file whose buffer is `chunks` (one bufferView each, 4-byte aligned), with `accessors`,
    one mesh of `primitives` (or `meshes`) on node 0 (or `nodes`) and an orthographic camera on the z axis
    at `camera_z` looking at the origin, seeing [-1, 1]^2; `extra` is merged into the document."""
    buf, views = b"", []
    for chunk in chunks:
        views.append({"buffer": 0, "byteOffset": len(buf), "byteLength": len(chunk)})
        buf += chunk + b"\0" * (-len(chunk) % 4)
    # A camera at -z looks back at the origin: rotated half a turn about y.
    cam_node = {"camera": 0, "translation": [0, 0, camera_z]}
    if camera_z < 0:
        cam_node["rotation"] = [0, 1, 0, 0]
    nodes = nodes if nodes is not None else [{"mesh": 0}]
    doc = {
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": list(range(len(nodes) + 1))}],
        "nodes": nodes + [cam_node],
        "cameras": [{"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 10}}],
        "meshes": meshes if meshes is not None else [{"primitives": primitives}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(buf), "uri": data_uri(buf)}],
    }
    if materials is not None:
        doc["materials"] = materials
    doc.update(extra or {})
    path.write_text(json.dumps(doc))
    return path


def vec_accessor(view, count, kind="VEC3", component=5126, **more):
    return {"bufferView": view, "componentType": component, "count": count, "type": kind, **more}


def load_warning_texts(path):
    """mr.load_scene(path) and the texts of the warnings it gave."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        scene, cameras = mr.load_scene(path)
    return scene, [str(w.message) for w in caught]


def render_color(path, size=48):
    """The colour render (one sample per pixel) of a file through its camera."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a file the loader reads fully gives no warning
        scene, cameras = mr.load_scene(path)
    return mr.render(scene, cameras[0], size, size).color, scene


# A zigzag ribbon in z = 0: with the spec's strip winding every triangle is counter-clockwise seen
# from +z (front-facing for the camera on +z).
STRIP = np.float32([[-0.9, 0.5, 0], [-0.9, -0.5, 0], [-0.3, 0.6, 0], [-0.3, -0.4, 0],
                    [0.3, 0.5, 0], [0.3, -0.6, 0], [0.9, 0.4, 0]])
# A fan: the centre, then rim points counter-clockwise seen from +z.
FAN = np.float32([[0, 0, 0], [0.8, 0, 0], [0.5, 0.6, 0], [0, 0.9, 0], [-0.6, 0.5, 0], [-0.8, -0.2, 0],
                  [0, -0.8, 0]])


def vertex_colors(n):
    rng = np.random.default_rng(n)
    return np.float32(rng.uniform(0.1, 1.0, (n, 4)))


def spec_triangles(mode, sequence):
    """glTF 2.0 §3.7.2.1, written out here as the oracle: strip triangle i is
    (v[i], v[i + (1 + i % 2)], v[i + (2 - i % 2)]), fan triangle i is (v[i + 1], v[i + 2], v[0])."""
    n = len(sequence)
    if mode == 5:
        return [(sequence[i], sequence[i + 1 + i % 2], sequence[i + 2 - i % 2]) for i in range(n - 2)]
    return [(sequence[i + 1], sequence[i + 2], sequence[0]) for i in range(n - 2)]


def write_assembled(path, mode, positions, indices=None, double_sided=False, camera_z=5.0):
    """`positions` (and COLOR_0) drawn as one primitive of `mode`, indexed when `indices` is given."""
    n = len(positions)
    chunks = [positions.tobytes(), vertex_colors(n).tobytes()]
    accessors = [vec_accessor(0, n), vec_accessor(1, n, "VEC4")]
    prim = {"attributes": {"POSITION": 0, "COLOR_0": 1}, "mode": mode, "material": 0}
    if indices is not None:
        chunks.append(np.uint16(indices).tobytes())
        accessors.append(vec_accessor(2, len(indices), "SCALAR", 5123))
        prim["indices"] = 2
    materials = [{"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1]}, "doubleSided": double_sided}]
    return write_mesh_gltf(path, chunks, accessors, [prim], materials, camera_z=camera_z)


@pytest.mark.parametrize("mode, positions", [(5, STRIP), (6, FAN)], ids=["strip", "fan"])
@pytest.mark.parametrize("indexed", [False, True])
def test_gltf_strips_and_fans_render_as_their_spec_triangles(tmp_path, mode, positions, indexed):
    n = len(positions)
    # Indexed: the vertices stored in a shuffled order, the index list putting them back.
    order = np.random.default_rng(3).permutation(n) if indexed else np.arange(n)
    stored = positions[order] if indexed else positions
    sequence = [int(np.flatnonzero(order == v)[0]) for v in range(n)] if indexed else list(range(n))
    path = write_assembled(tmp_path / "assembled.gltf", mode, stored, sequence if indexed else None)
    # The oracle: the same vertex buffer (and colours) drawn as TRIANGLES with the spec's index list.
    triangles = [v for tri in spec_triangles(mode, sequence) for v in tri]
    oracle = write_assembled(tmp_path / "triangles.gltf", 4, stored, triangles)
    got, scene = render_color(path)
    want, oracle_scene = render_color(oracle)
    np.testing.assert_array_equal(scene.draws[0].mesh.triangles, oracle_scene.draws[0].mesh.triangles)
    assert np.array_equal(got, want)
    assert (got[..., 3] > 0).sum() > 0.3 * got.shape[0] * got.shape[1]  # a real picture


@pytest.mark.parametrize("mode, positions", [(5, STRIP), (6, FAN)], ids=["strip", "fan"])
def test_gltf_single_sided_strip_and_fan_draw_every_triangle_from_the_front_only(tmp_path, mode, positions):
    # Culling is the independent check of the winding: seen from the front every triangle draws
    # (a strip whose odd triangles kept the stored order would lose them to back-face culling), and
    # seen from behind none does.
    size = 64
    front, scene = render_color(write_assembled(tmp_path / "front.gltf", mode, positions), size)
    back, _ = render_color(write_assembled(tmp_path / "back.gltf", mode, positions, camera_z=-5.0), size)
    assert len(scene.draws[0].mesh.triangles) == len(positions) - 2
    for tri in spec_triangles(mode, list(range(len(positions)))):
        x, y = positions[list(tri), :2].mean(axis=0)
        # The orthographic camera sees [-1, 1]^2: column (x + 1) / 2 * size, row (1 - y) / 2 * size.
        col, row = int((x + 1) / 2 * size), int((1 - y) / 2 * size)
        assert front[row, col, 3] == 1.0, (tri, row, col)
    assert (back[..., 3] == 0).all()


@pytest.mark.parametrize("mode", [5, 6])
@pytest.mark.parametrize("indexed", [False, True])
def test_gltf_strip_or_fan_of_fewer_than_three_vertices_warns(tmp_path, mode, indexed):
    positions = STRIP[:2]
    path = write_assembled(tmp_path / "short.gltf", mode, positions, [0, 1] if indexed else None)
    scene, texts = load_warning_texts(path)
    assert any(re.search(r"meshes\[0\]\.primitives\[0\]: a triangle (strip|fan) of 2 vertices has no triangle", t)
               for t in texts), texts
    assert len(scene.draws[0].mesh.triangles) == 0


@pytest.mark.parametrize("mode", [0, 1, 2, 3])
def test_gltf_points_and_lines_stay_skipped_with_a_warning(tmp_path, mode):
    path = write_assembled(tmp_path / "lines.gltf", mode, STRIP)
    scene, texts = load_warning_texts(path)
    assert any(re.search(r"skipped 1 primitive\(s\) of mode POINTS or LINES", t) for t in texts), texts
    assert scene.draws == [] or all(len(d.mesh.triangles) == 0 for d in scene.draws)


# Sparse accessors (glTF 2.0 §3.6.2.3).

QUAD = np.float32([[-0.8, 0.8, 0], [0.8, 0.8, 0], [0.8, -0.8, 0], [-0.8, -0.8, 0], [0, 0, 0], [0.5, 0.1, 0]])
QUAD_TRIANGLES = [0, 3, 4, 3, 2, 4, 2, 1, 5, 4, 2, 5, 1, 0, 5, 0, 4, 5]
QUAD_COLORS = vertex_colors(len(QUAD))


def sparse_block(count, indices_view, values_view, index_type=5125, indices_offset=0, values_offset=0):
    return {"count": count, "indices": {"bufferView": indices_view, "componentType": index_type,
                                        "byteOffset": indices_offset},
            "values": {"bufferView": values_view, "byteOffset": values_offset}}


INDEX_DTYPE = {5121: np.uint8, 5123: np.uint16, 5125: np.uint32}


def write_sparse_quad(path, replaced, index_type=5125, base=True, block=None, index_values=None):
    """QUAD as POSITION through a sparse accessor: the base values (QUAD with the `replaced` vertices
    moved away, or no bufferView: zeros) and a sparse block putting QUAD's values back at `replaced`."""
    base_values = QUAD.copy()
    base_values[replaced] = [5, 5, 5]  # far outside the view: a missed substitution shows
    index_values = replaced if index_values is None else index_values
    chunks = [QUAD_COLORS.tobytes(), np.uint16(QUAD_TRIANGLES).tobytes(),
              np.asarray(index_values, dtype=INDEX_DTYPE[index_type]).tobytes(), QUAD[replaced].tobytes()]
    position = {"componentType": 5126, "count": len(QUAD), "type": "VEC3", "name": "sparse_pos",
                "sparse": block or sparse_block(len(replaced), 2, 3, index_type)}
    if base:
        chunks.append(base_values.tobytes())
        position["bufferView"] = 4
    accessors = [position, vec_accessor(0, len(QUAD), "VEC4"), vec_accessor(1, len(QUAD_TRIANGLES), "SCALAR", 5123)]
    prim = {"attributes": {"POSITION": 0, "COLOR_0": 1}, "indices": 2}
    return write_mesh_gltf(path, chunks, accessors, [prim])


def write_dense_quad(path, positions):
    chunks = [positions.tobytes(), QUAD_COLORS.tobytes(), np.uint16(QUAD_TRIANGLES).tobytes()]
    accessors = [vec_accessor(0, len(QUAD)), vec_accessor(1, len(QUAD), "VEC4"),
                 vec_accessor(2, len(QUAD_TRIANGLES), "SCALAR", 5123)]
    return write_mesh_gltf(path, chunks, accessors, [{"attributes": {"POSITION": 0, "COLOR_0": 1}, "indices": 2}])


@pytest.mark.parametrize("index_type", [5121, 5123, 5125])
@pytest.mark.parametrize("base", [True, False], ids=["base-view", "zeros"])
def test_gltf_sparse_accessor_equals_the_dense_one(tmp_path, index_type, base):
    replaced = [0, 2, 5] if base else [0, 1, 2, 3, 5]  # without a base view: every non-zero vertex
    path = write_sparse_quad(tmp_path / "sparse.gltf", replaced, index_type, base)
    # The oracle: the base values with the sparse values substituted, written densely.
    dense = QUAD.copy() if base else np.zeros_like(QUAD)
    if base:
        dense[replaced] = [5, 5, 5]
    dense[replaced] = QUAD[replaced]
    got, scene = render_color(path)
    want, oracle = render_color(write_dense_quad(tmp_path / "dense.gltf", dense))
    np.testing.assert_array_equal(scene.draws[0].mesh.positions, oracle.draws[0].mesh.positions)
    np.testing.assert_array_equal(scene.draws[0].mesh.positions, QUAD)
    assert np.array_equal(got, want)
    assert (got[..., 3] > 0).mean() > 0.5


SPARSE_ERRORS = {
    # name: (edit of write_sparse_quad's arguments, the problem the message names)
    "index_out_of_range": (dict(index_values=[0, 2, 6]),
                           r"sparse index 6 \(element 2\) is out of range \(the accessor's count is 6\)"),
    "not_increasing": (dict(index_values=[0, 5, 2]), r"sparse indices are not strictly increasing.*5.*2"),
    "repeated_index": (dict(index_values=[0, 2, 2]), r"sparse indices are not strictly increasing"),
    "indices_outside_view": (dict(block=sparse_block(3, 2, 3, 5125, indices_offset=8)),
                             r"sparse indices: 3 elements need 12 bytes from byte offset 8, buffer view 2 has 12"),
    "values_outside_view": (dict(block=sparse_block(3, 2, 3, 5125, values_offset=4)),
                            r"sparse values: 3 elements need 36 bytes from byte offset 4, buffer view 3 has 36"),
    "values_view_missing": (dict(block=sparse_block(3, 2, 9)), r"sparse values: buffer view 9 does not exist"),
    "count_too_large": (dict(block=sparse_block(7, 2, 3)), r"sparse count 7 is larger than the accessor's count 6"),
    "count_zero": (dict(block=sparse_block(0, 2, 3)), r"sparse count 0 must be at least 1"),
    "index_type": (dict(block=sparse_block(3, 2, 3, 5126)), r"sparse indices must be unsigned byte, short or int"),
}


@pytest.mark.parametrize("case", sorted(SPARSE_ERRORS))
def test_gltf_bad_sparse_block_is_an_error_naming_the_accessor(tmp_path, case):
    edit, problem = SPARSE_ERRORS[case]
    path = write_sparse_quad(tmp_path / "bad_sparse.gltf", [0, 2, 5], **edit)
    with pytest.raises(OSError, match=r"bad_sparse\.gltf: .*POSITION \(accessor 0 'sparse_pos'\): " + problem):
        mr.load_scene(path)


def test_gltf_sparse_view_outside_its_buffer_is_an_error(tmp_path):
    path = write_sparse_quad(tmp_path / "outside.gltf", [0, 2, 5])
    doc = json.loads(path.read_text())
    doc["bufferViews"][3]["byteOffset"] = doc["buffers"][0]["byteLength"] - 8
    path.write_text(json.dumps(doc))
    with pytest.raises(OSError, match=r"\(accessor 0 'sparse_pos'\): sparse values: buffer view 3 .* lies outside "
                                      r"its buffer"):
        mr.load_scene(path)


def test_gltf_sparse_accessor_beyond_the_memory_limit_is_refused(tmp_path):
    # Without a base view, a few bytes of JSON can ask for count x element bytes of zeros: 4294967295
    # VEC3 floats are 48 GiB, above the default limit, refused before anything is allocated.
    path = write_sparse_quad(tmp_path / "huge.gltf", [0, 2, 5], base=False)
    doc = json.loads(path.read_text())
    doc["accessors"][0]["count"] = 2**32 - 1
    path.write_text(json.dumps(doc))
    with pytest.raises(mr.MemoryLimitError, match=r"huge\.gltf: .*\(accessor 0 'sparse_pos'\) \(a sparse accessor\) "
                                                  r"needs 48\.0 GiB"):
        mr.load_scene(path)


# Texture coordinate sets and KHR_texture_transform on the base colour texture.

QUAD_UVS = np.float32([[0, 0], [1, 0], [1, 1], [0, 1]])  # write_textured_gltf's uvs: (0, 0) top-left
REPEAT_NEAREST = {"magFilter": 9728, "minFilter": 9728}


def textured_variant(tmp_path, name, uv_sets, texture_info, materials_extra=None, extra=None):
    """write_textured_gltf with TEXCOORD_k = uv_sets[k] (float VEC2, one bufferView each after the
    quad's) and baseColorTexture = texture_info; nearest filtering with REPEAT wraps."""
    path = write_textured_gltf(tmp_path / name, {"uri": "checker.png"}, REPEAT_NEAREST)
    doc = json.loads(path.read_text())
    buf = base64.b64decode(doc["buffers"][0]["uri"].split(",", 1)[1])
    attributes = doc["meshes"][0]["primitives"][0]["attributes"]
    del attributes["TEXCOORD_0"]
    for k, uvs in enumerate(uv_sets):
        data = np.float32(uvs).tobytes()
        doc["bufferViews"].append({"buffer": 0, "byteOffset": len(buf), "byteLength": len(data)})
        doc["accessors"].append({"bufferView": len(doc["bufferViews"]) - 1, "componentType": 5126, "count": 4,
                                 "type": "VEC2"})
        attributes[f"TEXCOORD_{k}"] = len(doc["accessors"]) - 1
        buf += data
    doc["buffers"][0] = {"byteLength": len(buf), "uri": data_uri(buf)}
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = texture_info
    doc["materials"][0].update(materials_extra or {})
    doc.update(extra or {})
    path.write_text(json.dumps(doc))
    return path


def test_gltf_base_color_texture_on_texcoord_1(tmp_path):
    write_texture(tmp_path / "checker.png")
    flat = np.full((4, 2), 0.9, np.float32)  # TEXCOORD_0 would show one texel everywhere
    path = textured_variant(tmp_path, "uv1.gltf", [flat, QUAD_UVS], {"index": 0, "texCoord": 1})
    oracle = textured_variant(tmp_path, "uv0.gltf", [QUAD_UVS], {"index": 0})
    got, scene = render_color(path, 32)
    want, _ = render_color(oracle, 32)
    np.testing.assert_array_equal(scene.draws[0].mesh.uvs, QUAD_UVS)
    assert scene.draws[0].texture is not None
    assert np.array_equal(got, want)
    for q, expected in enumerate([TEXELS[0, 0], TEXELS[0, 1], TEXELS[1, 0], TEXELS[1, 1]]):
        np.testing.assert_allclose(quadrant_colors(got)[q], expected, atol=1e-6)


def test_gltf_missing_texcoord_n_draws_without_the_texture(tmp_path):
    write_texture(tmp_path / "checker.png")
    path = textured_variant(tmp_path, "uv2.gltf", [QUAD_UVS, QUAD_UVS], {"index": 0, "texCoord": 2})
    with pytest.warns(UserWarning, match=r"meshes\[0\]\.primitives\[0\] has no TEXCOORD_2 but its material "
                                         r"'checker' \(materials\[0\]\) has a baseColorTexture; "
                                         r"drawn without the texture"):
        scene, _ = mr.load_scene(path)
    assert scene.draws[0].texture is None


def test_gltf_texcoord_n_with_the_wrong_count_is_an_error(tmp_path):
    write_texture(tmp_path / "checker.png")
    path = textured_variant(tmp_path, "uv1_count.gltf", [QUAD_UVS, QUAD_UVS], {"index": 0, "texCoord": 1})
    doc = json.loads(path.read_text())
    doc["accessors"][-1]["count"] = 3
    path.write_text(json.dumps(doc))
    with pytest.raises(OSError, match=r"uv1_count\.gltf: .*TEXCOORD_1 \(accessor 4\): TEXCOORD_1 has 3 elements"):
        mr.load_scene(path)


def spec_uv_transform(uvs, offset=(0.0, 0.0), rotation=0.0, scale=(1.0, 1.0)):
    """KHR_texture_transform, written out here as the oracle: uv' = T(offset) R(rotation) S(scale) uv
    with R = [[cos, sin], [-sin, cos]] (the extension's example: offset (0, 1), rotation pi/2, scale
    1/2 maps the unit square onto the image's lower-left quadrant, v down)."""
    u, v = np.float64(uvs).T * np.float64(scale)[:, None]
    c, s = math.cos(rotation), math.sin(rotation)
    return np.float32(np.stack([c * u + s * v + offset[0], -s * u + c * v + offset[1]], axis=1))


TRANSFORMS = {
    "offset": dict(offset=[0.5, 0.25]),
    "scale": dict(scale=[2.0, -3.0]),
    "rotation": dict(rotation=0.7),
    "all": dict(offset=[-0.3, 1.2], rotation=-2.1, scale=[1.5, 0.75]),
}


@pytest.mark.parametrize("name", sorted(TRANSFORMS))
def test_gltf_texture_transform_equals_uvs_transformed_by_the_spec(tmp_path, name):
    write_texture(tmp_path / "checker.png")
    transform = TRANSFORMS[name]
    info = {"index": 0, "extensions": {"KHR_texture_transform": transform}}
    path = textured_variant(tmp_path, "transform.gltf", [QUAD_UVS], info,
                            extra={"extensionsUsed": ["KHR_texture_transform"]})
    expected_uvs = spec_uv_transform(QUAD_UVS, **transform)
    oracle = textured_variant(tmp_path, "transformed_uvs.gltf", [expected_uvs], {"index": 0})
    got, scene = render_color(path, 32)
    want, _ = render_color(oracle, 32)
    np.testing.assert_allclose(scene.draws[0].mesh.uvs, expected_uvs, rtol=0, atol=1e-6)
    assert np.array_equal(got, want)


def test_gltf_texture_transform_follows_the_extensions_example(tmp_path):
    # The extension's README: offset (0, 1), rotation pi/2, scale 1/2 "utilizes only the lower left
    # quadrant of the source image": the 2x2 checker's blue texel fills the quad.
    write_texture(tmp_path / "checker.png")
    transform = {"offset": [0, 1], "rotation": math.pi / 2, "scale": [0.5, 0.5]}
    info = {"index": 0, "extensions": {"KHR_texture_transform": transform}}
    got, _ = render_color(textured_variant(tmp_path, "example.gltf", [QUAD_UVS], info), 32)
    inner = got[2:-2, 2:-2].reshape(-1, 4)
    np.testing.assert_allclose(inner, np.tile(TEXELS[1, 0], (len(inner), 1)), atol=1e-6)


def test_gltf_texture_transform_texcoord_overrides_the_texture_infos(tmp_path):
    write_texture(tmp_path / "checker.png")
    flat = np.full((4, 2), 0.9, np.float32)
    transform = {"texCoord": 1, "scale": [0.5, 0.5]}
    info = {"index": 0, "texCoord": 0, "extensions": {"KHR_texture_transform": transform}}
    path = textured_variant(tmp_path, "override.gltf", [flat, QUAD_UVS], info)
    got, scene = render_color(path, 32)
    np.testing.assert_allclose(scene.draws[0].mesh.uvs, spec_uv_transform(QUAD_UVS, scale=(0.5, 0.5)))
    inner = got[2:-2, 2:-2].reshape(-1, 4)
    np.testing.assert_allclose(inner, np.tile(TEXELS[0, 0], (len(inner), 1)), atol=1e-6)  # all the red texel


def test_gltf_texture_transform_does_not_leak_to_primitives_sharing_its_accessors(tmp_path):
    # One mesh with two primitives on the same accessors, one material transformed and one not, and
    # two nodes drawing that mesh: every draw gets its own material's uvs.
    write_texture(tmp_path / "checker.png")
    transform = {"offset": [0.25, 0.5]}
    path = textured_variant(tmp_path, "shared.gltf", [QUAD_UVS],
                            {"index": 0, "extensions": {"KHR_texture_transform": transform}})
    doc = json.loads(path.read_text())
    plain = dict(doc["materials"][0], name="plain",
                 pbrMetallicRoughness={"baseColorTexture": {"index": 0}})
    doc["materials"].append(plain)
    prim = doc["meshes"][0]["primitives"][0]
    doc["meshes"][0]["primitives"] = [prim, dict(prim, material=1), prim]
    doc["nodes"].append({"mesh": 0, "translation": [0, 0, 1]})
    doc["scenes"][0]["nodes"].append(len(doc["nodes"]) - 1)
    path.write_text(json.dumps(doc))
    scene, _ = mr.load_scene(path)
    assert len(scene.draws) == 6
    # The second node's draws share the first node's meshes; the primitives do not share one.
    assert all(scene.draws[i].mesh is scene.draws[i + 3].mesh for i in range(3))
    assert len({id(d.mesh) for d in scene.draws}) == 3
    moved = spec_uv_transform(QUAD_UVS, offset=(0.25, 0.5))
    for d, uvs in zip(scene.draws, [moved, QUAD_UVS, moved] * 2):
        np.testing.assert_allclose(d.mesh.uvs, uvs, rtol=0, atol=1e-6)


TRANSFORM_ERRORS = {
    "offset_length": ({"offset": [0.5]}, r"KHR_texture_transform offset must be 2 finite numbers"),
    "scale_length": ({"scale": [1, 2, 3]}, r"KHR_texture_transform scale must be 2 finite numbers"),
    "scale_type": ({"scale": [1, "x"]}, r"KHR_texture_transform scale must be 2 finite numbers"),
    "offset_object": ({"offset": {"u": 1, "v": 2}}, r"KHR_texture_transform offset must be 2 finite numbers"),
    "rotation_type": ({"rotation": [1]}, r"KHR_texture_transform rotation must be a finite number"),
    "rotation_string": ({"rotation": "0.5"}, r"KHR_texture_transform rotation must be a finite number"),
    "texcoord": ({"texCoord": -1}, r"KHR_texture_transform texCoord must be an integer >= 0"),
    "texcoord_real": ({"texCoord": 1.5}, r"KHR_texture_transform texCoord must be an integer >= 0"),
}
# (Non-finite values cannot reach the loader: JSON has none, and tinygltf's parser rejects 1e999.)


@pytest.mark.parametrize("case", sorted(TRANSFORM_ERRORS))
def test_gltf_bad_texture_transform_is_an_error_naming_the_material(tmp_path, case):
    write_texture(tmp_path / "checker.png")
    transform, problem = TRANSFORM_ERRORS[case]
    info = {"index": 0, "extensions": {"KHR_texture_transform": transform}}
    path = textured_variant(tmp_path, "bad_transform.gltf", [QUAD_UVS], info)
    with pytest.raises(OSError, match=r"bad_transform\.gltf: material 'checker' \(materials\[0\]\): " + problem):
        mr.load_scene(path)


# extensionsRequired: an extension the loader cannot honour stops the load with a message naming it.

@pytest.mark.parametrize("extension", ["KHR_draco_mesh_compression", "EXT_meshopt_compression",
                                       "KHR_texture_basisu"])
def test_gltf_required_extension_that_is_not_supported_is_named(tmp_path, extension):
    path = write_gltf(tmp_path / "required.gltf")
    doc = json.loads(path.read_text())
    doc["extensionsUsed"] = doc["extensionsRequired"] = ["KHR_texture_transform", extension]
    if extension == "KHR_draco_mesh_compression":  # as compressed files are: accessors without views
        for a in doc["accessors"]:
            del a["bufferView"]
    elif extension == "EXT_meshopt_compression":  # a fallback buffer without data
        doc["buffers"].append({"byteLength": 64})
    path.write_text(json.dumps(doc))
    with pytest.raises(OSError, match=rf"required\.gltf: the file requires the glTF extension '{extension}', "
                                      r"which this loader does not support"):
        mr.load_scene(path)


@pytest.mark.parametrize("extension", ["KHR_texture_transform", "KHR_materials_unlit", "KHR_mesh_quantization",
                                       "EXT_mesh_gpu_instancing", "EXT_texture_webp"])
def test_gltf_required_extension_that_is_supported_loads(tmp_path, extension):
    path = write_gltf(tmp_path / "required_ok.gltf")
    doc = json.loads(path.read_text())
    doc["extensionsUsed"] = doc["extensionsRequired"] = [extension]
    path.write_text(json.dumps(doc))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        scene, _ = mr.load_scene(path)
    assert len(scene.draws[0].mesh.triangles) == 1


# extensionsUsed: an extension that changes what the file looks like and that the loader does not
# apply is named once; those that cannot change an unlit base-colour render (lighting and material
# effects, lights), whose fallback is drawn (compression, image formats, detail levels) or that the
# loader applies are not.

def test_gltf_used_extensions_the_loader_does_not_apply_are_warned_about_once(tmp_path):
    used = ["KHR_materials_pbrSpecularGlossiness", "KHR_node_visibility", "VENDOR_made_up_effect",
            "KHR_materials_pbrSpecularGlossiness",  # listed twice: still one warning
            "EXT_mesh_gpu_instancing", "KHR_texture_transform", "KHR_materials_unlit", "KHR_mesh_quantization",
            "KHR_materials_sheen", "KHR_materials_clearcoat", "KHR_materials_transmission", "KHR_materials_volume",
            "KHR_materials_ior", "KHR_materials_specular", "KHR_materials_emissive_strength",
            "KHR_materials_iridescence", "KHR_materials_anisotropy", "KHR_materials_variants",
            "KHR_lights_punctual", "EXT_lights_image_based", "KHR_draco_mesh_compression", "EXT_meshopt_compression",
            "KHR_texture_basisu", "EXT_texture_webp", "EXT_texture_avif", "MSFT_lod", "KHR_animation_pointer",
            "KHR_xmp_json_ld"]
    path = write_gltf(tmp_path / "used.gltf")
    doc = json.loads(path.read_text())
    doc["extensionsUsed"] = used
    path.write_text(json.dumps(doc))
    scene, texts = load_warning_texts(path)
    assert len(scene.draws) == 1
    named = sorted(re.search(r"glTF extension '([^']*)'", t).group(1) for t in texts)
    assert named == ["KHR_materials_pbrSpecularGlossiness", "KHR_node_visibility", "VENDOR_made_up_effect"], texts
    for text in texts:
        assert text.startswith(str(path) + ": the file uses the glTF extension '")
        assert "which this loader does not apply: " in text
    assert any("diffuseFactor and diffuseTexture" in t for t in texts)
    assert any("the nodes it hides are drawn" in t for t in texts)
    assert any("this loader does not know it" in t for t in texts)


def test_gltf_mesh_quantization_texcoords(tmp_path):
    # KHR_mesh_quantization allows TEXCOORD_n as (normalized or not) byte/short and unnormalized
    # unsigned byte/short; the values are the integers (normalized: divided by 127 / 32767).
    write_texture(tmp_path / "checker.png")
    cases = [(5120, True, [0, 0, 127, 0, 127, 127, 0, 127], np.int8),
             (5122, True, [0, 0, 32767, 0, 32767, 32767, 0, 32767], np.int16),
             (5120, False, [0, 0, 1, 0, 1, 1, 0, 1], np.int8),
             (5121, False, [0, 0, 1, 0, 1, 1, 0, 1], np.uint8),
             (5122, False, [0, 0, 1, 0, 1, 1, 0, -1], np.int16),
             (5123, False, [0, 0, 1, 0, 1, 1, 0, 1], np.uint16)]
    for k, (component, normalized, values, dtype) in enumerate(cases):
        path = textured_variant(tmp_path, f"quantized{k}.gltf", [QUAD_UVS], {"index": 0},
                                extra={"extensionsUsed": ["KHR_mesh_quantization"],
                                       "extensionsRequired": ["KHR_mesh_quantization"]})
        doc = json.loads(path.read_text())
        data = np.asarray(values, dtype=dtype).tobytes()
        data += b"\0" * (-len(data) % 4)
        buf = base64.b64decode(doc["buffers"][0]["uri"].split(",", 1)[1])
        doc["bufferViews"].append({"buffer": 0, "byteOffset": len(buf), "byteLength": len(data)})
        buf += data
        doc["buffers"][0] = {"byteLength": len(buf), "uri": data_uri(buf)}
        doc["accessors"][-1] = {"bufferView": len(doc["bufferViews"]) - 1, "componentType": component,
                                "normalized": normalized, "count": 4, "type": "VEC2"}
        path.write_text(json.dumps(doc))
        scene, _ = mr.load_scene(path)
        scale = (127.0 if dtype == np.int8 else 32767.0) if normalized else 1.0
        np.testing.assert_allclose(scene.draws[0].mesh.uvs, np.float32(values).reshape(4, 2) / scale,
                                   err_msg=str((component, normalized)))
        assert scene.draws[0].texture is not None


# --- morph targets and skins (their rest pose: the nodes' own transforms, no animation) ----------

TRIANGLE = np.float32([[-0.5, -0.5, 0], [0.5, -0.5, 0], [0, 0.5, 0]])


def test_gltf_morph_targets_at_the_node_or_mesh_default_weights(tmp_path):
    # Positions = base + Σ weight_t · target_t (the spec's morphing), per node: the mesh's default
    # weights (0.25, 0.5), a node's own (1, 0) and all zero (the base shape).
    rng = np.random.default_rng(44)
    targets = rng.uniform(-0.3, 0.3, (2, 3, 3)).astype(np.float32)
    chunks = [TRIANGLE.tobytes(), targets[0].tobytes(), targets[1].tobytes()]
    accessors = [vec_accessor(0, 3, min=[-0.5, -0.5, 0], max=[0.5, 0.5, 0]), vec_accessor(1, 3), vec_accessor(2, 3)]
    primitive = {"attributes": {"POSITION": 0}, "targets": [{"POSITION": 1}, {"POSITION": 2}]}
    meshes = [{"primitives": [primitive], "weights": [0.25, 0.5]}]
    nodes = [{"mesh": 0}, {"mesh": 0, "weights": [1.0, 0.0]}, {"mesh": 0, "weights": [0.0, 0.0]}]
    scene, _ = mr.load_scene(write_mesh_gltf(tmp_path / "morph.gltf", chunks, accessors, None, meshes=meshes,
                                             nodes=nodes))
    base = TRIANGLE.astype(np.float64)
    for draw, w in zip(scene.draws, [(0.25, 0.5), (1.0, 0.0), (0.0, 0.0)]):
        want = base + w[0] * targets[0].astype(np.float64) + w[1] * targets[1].astype(np.float64)
        np.testing.assert_allclose(draw.mesh.positions, want.astype(np.float32), rtol=0, atol=1e-7, err_msg=str(w))
    bad = write_mesh_gltf(tmp_path / "bad.gltf", chunks, accessors, None, meshes=meshes,
                          nodes=[{"mesh": 0, "weights": [1.0]}])
    with pytest.raises(OSError, match=r"bad\.gltf: node 0: its weights has 1 entries for 2 morph targets"):
        mr.load_scene(bad)


def test_gltf_morph_targets_move_texcoords_and_colours_as_the_spec_says(tmp_path):
    # TEXCOORD_n and COLOR_n deltas (the spec's optional morphs) add up as POSITION's: uv = base +
    # Σ w·Δ before the texture transform maps it; colour = clamp(base + Σ w·Δ, 0, 1) (a VEC3 delta
    # leaves alpha), then premultiplied where the material blends (mesh 0; mesh 1's plain material
    # has no texture to transform for). Deltas in float and normalized byte/short; a negative
    # weight; the numpy sums below are the oracle.
    write_texture(tmp_path / "checker.png")
    rng = np.random.default_rng(47)
    uvs = rng.uniform(0, 1, (3, 2)).astype(np.float32)
    colours = np.float32([[0.2, 0.9, 0.5, 0.8], [0.95, 0.1, 0.4, 0.3], [0.5, 0.5, 0.05, 1.0]])
    duv0 = rng.uniform(-0.5, 0.5, (3, 2)).astype(np.float32)
    duv1 = rng.integers(-127, 128, (3, 2)).astype(np.int8)  # normalized: /127
    dcol0 = np.float32([[0.5, -0.4, 0.1], [0.2, 0.3, -0.9], [-0.1, 0.0, 0.6]])  # VEC3: alpha unmoved
    dcol1 = rng.integers(-32767, 32768, (3, 4)).astype(np.int16)  # normalized: /32767
    chunks = [TRIANGLE.tobytes(), uvs.tobytes(), colours.tobytes(), duv0.tobytes(), duv1.tobytes(),
              dcol0.tobytes(), dcol1.tobytes()]
    accessors = [vec_accessor(0, 3, min=[-0.5, -0.5, 0], max=[0.5, 0.5, 0]), vec_accessor(1, 3, "VEC2"),
                 vec_accessor(2, 3, "VEC4"), vec_accessor(3, 3, "VEC2"),
                 vec_accessor(4, 3, "VEC2", 5120, normalized=True), vec_accessor(5, 3, "VEC3"),
                 vec_accessor(6, 3, "VEC4", 5122, normalized=True)]
    targets = [{"TEXCOORD_0": 3, "COLOR_0": 5}, {"TEXCOORD_0": 4, "COLOR_0": 6}]
    transform = {"offset": [0.25, -0.5], "rotation": 0.3, "scale": [2.0, 0.5]}
    texture = {"index": 0, "extensions": {"KHR_texture_transform": transform}}
    materials = [{"alphaMode": "BLEND", "pbrMetallicRoughness": {"baseColorTexture": texture}}, {}]
    meshes = [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1, "COLOR_0": 2}, "targets": targets,
                               "material": m}]} for m in (0, 1)]
    weights = [(0.75, -0.5), (1.0, 0.0), (0.0, 0.0)]
    nodes = [{"mesh": 0, "weights": list(weights[0])}, {"mesh": 0, "weights": list(weights[1])},
             {"mesh": 0, "weights": list(weights[2])}, {"mesh": 1, "weights": list(weights[0])}]
    path = write_mesh_gltf(tmp_path / "morph_uv_colour.gltf", chunks, accessors, None, materials, meshes=meshes,
                           nodes=nodes, extra={"textures": [{"source": 0}], "images": [{"uri": "checker.png"}],
                                               "extensionsUsed": ["KHR_texture_transform"]})
    scene, _ = mr.load_scene(path)
    assert len(scene.draws) == 4
    steps1 = np.maximum(duv1 / 127.0, -1.0), np.maximum(dcol1 / 32767.0, -1.0)
    for draw, (w0, w1), blends in zip(scene.draws, weights + [weights[0]], [True, True, True, False]):
        want_uv = uvs.astype(np.float64) + w0 * duv0 + w1 * steps1[0]
        want_uv = spec_uv_transform(want_uv, **transform) if blends else want_uv
        np.testing.assert_allclose(draw.mesh.uvs, want_uv, rtol=0, atol=1e-6, err_msg=str((w0, w1)))
        moved = colours.astype(np.float64) + w0 * np.hstack([dcol0, np.zeros((3, 1))]) + w1 * steps1[1]
        moved = np.clip(moved, 0.0, 1.0) if (w0, w1) != (0.0, 0.0) else moved
        alpha = moved[:, 3:] if blends else np.ones((3, 1))
        want_colour = np.hstack([moved[:, :3] * alpha, alpha])
        np.testing.assert_allclose(draw.mesh.colors, want_colour, rtol=0, atol=1e-7, err_msg=str((w0, w1, blends)))
    assert (np.asarray(scene.draws[0].mesh.colors) == 0).any()  # the clamp acted (below 0)
    assert (np.asarray(scene.draws[1].mesh.colors)[:, :3] == np.asarray(scene.draws[1].mesh.colors)[:, 3:]).any()

    # A delta accessor of the wrong type or component type is an error naming it.
    for k, (accessor, message) in enumerate([(vec_accessor(5, 3, "VEC2"), r"COLOR_0 must be VEC3 or VEC4"),
                                             (vec_accessor(5, 3, "VEC3"), r"TEXCOORD_0 must be VEC2"),
                                             (vec_accessor(4, 3, "VEC2", 5120), r"TEXCOORD_0 deltas must be float "
                                              r"or normalized byte/short, got component type 5120")]):
        bad_accessors = accessors + [accessor]
        bad_targets = [{"TEXCOORD_0": 3, "COLOR_0": 5}, dict(targets[1])]
        bad_targets[1]["COLOR_0" if "COLOR" in message else "TEXCOORD_0"] = len(accessors)
        bad_meshes = [{"primitives": [{**meshes[0]["primitives"][0], "targets": bad_targets}]}]
        bad = write_mesh_gltf(tmp_path / f"bad{k}.gltf", chunks, bad_accessors, None, materials, meshes=bad_meshes,
                              nodes=[{"mesh": 0, "weights": [0.5, 0.5]}],
                              extra={"textures": [{"source": 0}], "images": [{"uri": "checker.png"}]})
        with pytest.raises(OSError, match=rf"bad{k}\.gltf: .*targets\[1\] .*\(accessor 7\): " + message):
            mr.load_scene(bad)


def trs(translation=(0, 0, 0), rotation=(0, 0, 0, 1), scale=(1, 1, 1)):
    """glTF's T · R · S of a node (rotation a unit quaternion x, y, z, w), as numpy does it."""
    x, y, z, w = rotation
    r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                  [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                  [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    m = np.eye(4)
    m[:3, :3] = r * np.asarray(scale, float)
    m[:3, 3] = translation
    return m


def test_gltf_skin_places_vertices_by_their_joints_at_rest(tmp_path):
    # Linear blend skinning at the joints' own transforms: v' = Σ w_j · (global_j · inverseBind_j) · v,
    # the skinned node's own transform ignored (the spec). Joint 1 is joint 0's child; weights
    # spread one vertex over both joints and sit in two sets (JOINTS_1 / WEIGHTS_1).
    half = np.sqrt(0.5)
    joint0 = {"translation": [0.1, 0.2, 0.0], "rotation": [0, 0, half, half], "children": [2]}
    joint1 = {"translation": [0.0, 0.3, 0.0], "scale": [0.5, 0.5, 0.5]}
    inverse_bind = [np.linalg.inv(trs((0.05, 0, 0))), np.linalg.inv(trs((0, 0.1, 0), scale=(2, 2, 2)))]
    joints = np.uint8([[0, 1, 0, 0], [0, 1, 0, 0], [1, 0, 0, 0]])
    weights = np.float32([[1, 0, 0, 0], [0.25, 0.5, 0, 0], [0.5, 0, 0, 0]])
    joints1 = np.uint8([[0, 0, 0, 0], [0, 0, 0, 0], [0, 0, 0, 0]])
    weights1 = np.float32([[0, 0, 0, 0], [0.25, 0, 0, 0], [0.5, 0, 0, 0]])
    ibm = np.float32([m.T for m in inverse_bind])  # column-major MAT4s
    chunks = [TRIANGLE.tobytes(), joints.tobytes(), weights.tobytes(), joints1.tobytes(), weights1.tobytes(),
              ibm.tobytes()]
    accessors = [vec_accessor(0, 3, min=[-0.5, -0.5, 0], max=[0.5, 0.5, 0]), vec_accessor(1, 3, "VEC4", 5121),
                 vec_accessor(2, 3, "VEC4"), vec_accessor(3, 3, "VEC4", 5121), vec_accessor(4, 3, "VEC4"),
                 vec_accessor(5, 2, "MAT4")]
    primitive = {"attributes": {"POSITION": 0, "JOINTS_0": 1, "WEIGHTS_0": 2, "JOINTS_1": 3, "WEIGHTS_1": 4}}
    nodes = [{"mesh": 0, "skin": 0, "translation": [100, 0, 0]}, joint0, joint1]
    path = write_mesh_gltf(tmp_path / "skin.gltf", [*chunks], accessors, [primitive], nodes=nodes,
                           extra={"skins": [{"joints": [1, 2], "inverseBindMatrices": 5}]})
    doc = json.loads(path.read_text())
    doc["scenes"] = [{"nodes": [0, 1, 3]}]  # (joint 1 is only joint 0's child)
    path.write_text(json.dumps(doc))
    scene, _ = mr.load_scene(path)

    global0 = trs((0.1, 0.2, 0), (0, 0, half, half))
    global1 = global0 @ trs((0, 0.3, 0), scale=(0.5, 0.5, 0.5))
    skinning = [global0 @ inverse_bind[0], global1 @ inverse_bind[1]]
    want = []
    for v, js, ws in zip(TRIANGLE, np.hstack([joints, joints1]), np.hstack([weights, weights1])):
        m = sum(float(w) * skinning[j] for j, w in zip(js, ws))
        want.append((m @ np.append(v.astype(np.float64), 1.0))[:3])
    (draw,) = scene.draws
    np.testing.assert_allclose(draw.model, np.eye(4))
    np.testing.assert_allclose(draw.mesh.positions, np.float32(want), rtol=0, atol=1e-6)

    doc["skins"][0]["joints"] = [1, 7]
    path.write_text(json.dumps(doc))
    with pytest.raises(OSError, match=r"skin\.gltf: skins\[0\]: joint 1 is node 7, which does not exist"):
        mr.load_scene(path)
