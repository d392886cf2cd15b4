"""mipraster.load_scene and `mipraster render SCENE`: OBJ and glTF files written by the tests."""
import base64
import json
import math
import os
import struct
import subprocess

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
