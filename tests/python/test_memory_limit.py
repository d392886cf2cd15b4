"""The process-wide memory limit seen from Python: renders, rasterizations and textures estimated
above it raise MemoryLimitError (a ValueError and a MemoryError) giving the estimate and the limit,
before anything large is allocated."""
import re
import resource
import struct
import warnings

import numpy as np
import pytest

import mipraster as mr


@pytest.fixture
def limit():
    """Sets the limit for one test and restores the default after it."""
    yield mr.set_memory_limit
    mr.set_memory_limit(0)


def triangle_scene():
    scene = mr.Scene()
    scene.add(mr.Mesh([[-0.5, -0.5, 0], [0.5, -0.5, 0], [0, 0.5, 0]], [[0, 1, 2]]))
    return scene


def reported_bytes(message):
    return int(re.search(r"\((\d+) bytes\)", message).group(1))


def test_default_and_restore(limit):
    assert mr.memory_limit() == mr._core.DEFAULT_MEMORY_LIMIT == 16 << 30
    limit(12345)
    assert mr.memory_limit() == 12345
    limit(0)
    assert mr.memory_limit() == 16 << 30
    with pytest.raises(ValueError, match="memory limit: expected bytes >= 0"):
        mr.set_memory_limit(-1)
    with pytest.raises(ValueError, match=r"memory limit: 1180591620717411303424 bytes is beyond 2\^64 - 1"):
        mr.set_memory_limit(2**70)  # (was pybind11's "incompatible function arguments")
    with pytest.raises(TypeError, match="memory limit: expected an integer, got bool True"):
        mr.set_memory_limit(True)
    limit(2**64 - 1)
    assert mr.memory_limit() == 2**64 - 1


def test_render_refused_with_estimate_and_limit(limit):
    scene, camera = triangle_scene(), mr.Camera.look_at((0, 0, 2), (0, 0, 0))
    limit(1 << 20)
    with pytest.raises(mr.MemoryLimitError) as e:
        mr.render(scene, camera, 1000, 1000, spp=4, threads=1)
    message = str(e.value)
    assert "a render of 1000x1000 pixels at 4 samples per pixel needs" in message
    assert "the memory limit is 1.00 MiB" in message
    assert isinstance(e.value, MemoryError) and isinstance(e.value, ValueError)
    # At least the resolved colour image; at the estimate itself the render goes ahead.
    needed = reported_bytes(message)
    assert needed >= 1000 * 1000 * 16
    limit(needed)
    assert mr.render(scene, camera, 1000, 1000, spp=4, threads=1).color.shape == (1000, 1000, 4)


def test_keeping_samples_adds_the_sample_buffer(limit):
    scene, camera = triangle_scene(), mr.Camera.look_at((0, 0, 2), (0, 0, 0))
    limit(1)
    sizes = {}
    for keep in (False, True):
        with pytest.raises(mr.MemoryLimitError) as e:
            mr.render(scene, camera, 64, 32, spp=8, threads=1, keep_samples=keep)
        sizes[keep] = reported_bytes(str(e.value))
    # colour and depth (the draw tests depth): 20 bytes a sample
    assert sizes[True] - sizes[False] == 64 * 32 * 8 * 20


def test_error_probe_draws_are_counted(limit):
    # The probe's draws are with replacement, so probe_pixels may exceed the image's pixels; their
    # bookkeeping (72 bytes a draw) is checked against the limit before it is allocated.
    scene, camera = triangle_scene(), mr.Camera.look_at((0, 0, 2), (0, 0, 0))
    limit(100 << 20)  # the render fits; 10⁷ draws (720 MB) do not
    with pytest.raises(mr.MemoryLimitError, match="the error probe's 10000000 probe_pixels needs") as e:
        mr.render(scene, camera, 16, 16, spp=4, threads=1, estimate_error=True, probe_pixels=10**7)
    assert reported_bytes(str(e.value)) == 10**7 * 72 + 16 * 16 * 8
    r = mr.render(scene, camera, 16, 16, spp=4, threads=1, estimate_error=True, probe_pixels=64)
    assert r.error_probe.pixels == 64


def test_rasterize_and_texture_refused(limit):
    limit(1 << 20)
    with pytest.raises(mr.MemoryLimitError, match="rasterizing 1000x1000 pixels at 1 sample per pixel needs"):
        mr.rasterize(np.array([[-1, -1, 0, 1], [1, -1, 0, 1], [0, 1, 0, 1]], np.float32), [[0, 1, 2]], 1000, 1000)
    with pytest.raises(mr.MemoryLimitError, match=r"texture 'wall' \(512x512, RGBA float with its mip chain\) needs 5.33 MiB"):
        mr.Texture(np.zeros((512, 512, 4), np.uint8), name="wall")


def test_image_read_refused_before_decoding(limit, tmp_path):
    # An image file's header gives its size: reading it is refused above the limit, with the
    # size in the message, and goes ahead at the estimate (stored channels, then RGBA float).
    path = tmp_path / "grey.png"
    mr.write_image(path, np.full((300, 200, 4), 0.5, np.float32))
    limit(1 << 16)
    with pytest.raises(mr.MemoryLimitError, match=r"reading '.*grey\.png' \(200x300x4\) needs"):
        mr.read_image(path)
    needed = 200 * 300 * 4 * 5 + 200 * 300 * 16
    limit(needed)
    assert mr.read_image(path).shape == (300, 200, 4)
    limit(needed - 1)
    with pytest.raises(mr.MemoryLimitError):
        mr.read_image(path)


def gif(width, height):
    """A GIF of one 1x1 black frame on a width x height logical screen (header, two-colour
    palette, image descriptor, LZW data, trailer)."""
    header = b"GIF89a" + struct.pack("<HHBBB", width, height, 0x80, 0, 0) + bytes(6)
    return header + b"\x2c" + struct.pack("<HHHHB", 0, 0, 1, 1, 0) + b"\x02\x02\x44\x01\x00\x3b"


def test_gif_screen_size_refused_before_decoding(limit, tmp_path):
    # OpenImageIO's GIF reader allocates the logical screen as it opens the file: its header is
    # judged first, as other formats' are (a 40-byte file claiming 20000² pixels took 1.6 GB).
    small = tmp_path / "small.gif"
    small.write_bytes(gif(3, 2))
    assert mr.read_image(small).shape == (2, 3, 4)
    big = tmp_path / "big.gif"
    big.write_bytes(gif(20000, 20000))
    limit(64 << 20)
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    with pytest.raises(mr.MemoryLimitError, match=r"reading '.*big\.gif' \(20000x20000x4\) needs"):
        mr.read_image(big)
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before < 64 << 10  # (KiB)
    huge = tmp_path / "huge.gif"
    huge.write_bytes(gif(30000, 30000))
    with pytest.raises(OSError, match=r"huge\.gif' is too large \(30000x30000 pixels"):
        mr.read_image(huge)


def test_scene_file_textures_within_the_limit(limit, tmp_path):
    # Scene files load in the OpenImageIO module, which has its own copy of the limit: the limit
    # set here reaches it too (the texture image is refused while reading the scene).
    mr.write_image(tmp_path / "big.png", np.full((400, 400, 3), 0.5, np.float32))
    (tmp_path / "quad.mtl").write_text("newmtl m\nKd 1 1 1\nmap_Kd big.png\n")
    (tmp_path / "quad.obj").write_text("mtllib quad.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
                                       "usemtl m\nf 1/1 2/2 3/3\n")
    limit(1 << 20)
    with pytest.warns(UserWarning, match="big.png"):
        mr.load_scene(tmp_path / "quad.obj")
    limit(0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        mr.load_scene(tmp_path / "quad.obj")


def test_kept_buffers_are_counted_and_released():
    """A render's large buffers stay for the next render of their size, counted by
    kept_buffer_bytes() and freed by release_kept_buffers(); neither changes what is rendered."""
    scene = triangle_scene()
    camera = mr.Camera.look_at((0, 0, 2), (0, 0, 0))
    mr.release_kept_buffers()
    assert mr.kept_buffer_bytes() == 0
    first = mr.render(scene, camera, 1024, 1024).color.copy()  # a 16 MiB colour image
    assert mr.kept_buffer_bytes() >= 1024 * 1024 * 4 * 4  # (freed with the result: kept)
    again = mr.render(scene, camera, 1024, 1024).color  # into the kept block
    assert np.array_equal(again, first)
    mr.release_kept_buffers()
    assert mr.kept_buffer_bytes() == 0
    assert np.array_equal(mr.render(scene, camera, 1024, 1024).color, first)
