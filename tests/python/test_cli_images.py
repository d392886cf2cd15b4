"""The `mipraster resize` and `mipraster synthesize` commands, and `render --resolve`: outputs
against the Python API on the same input, and the messages and exit statuses of bad input."""
import numpy as np
import pytest
from PIL import Image

import mipraster as mr
from test_cli import run


def write_png(path, codes):
    Image.fromarray(codes).save(path)
    return str(path)


def test_resize_matches_the_python_api(tmp_path):
    rng = np.random.default_rng(1)
    codes = rng.integers(0, 256, (40, 56, 3), dtype=np.uint8)
    src = write_png(tmp_path / "in.png", codes)
    for filter in ("box", "lanczos3"):
        out = tmp_path / f"out_{filter}.png"
        r = run("resize", src, "-o", str(out), "--size", "23x17", "--filter", filter)
        assert r.returncode == 0, r.stderr
        assert f"23x17 from 56x40, {filter}" in r.stdout
        got = np.asarray(Image.open(out))[..., :3].astype(int)
        expected = mr.resample(codes, (23, 17), filter=filter).astype(int)
        assert np.abs(got - expected).max() <= 1  # the same filtering; the CLI encodes from float32 too


def test_synthesize_copies_sample_pixels_and_repeats_for_a_seed(tmp_path):
    rng = np.random.default_rng(2)
    codes = rng.integers(0, 256, (24, 24, 3), dtype=np.uint8)
    src = write_png(tmp_path / "sample.png", codes)
    outs = []
    for name in ("a.png", "b.png"):
        out = tmp_path / name
        r = run("synthesize", src, "-o", str(out), "--size", "40x30", "--window", "7", "--seed", "5")
        assert r.returncode == 0, r.stderr
        assert "40x30" in r.stdout and "window 7" in r.stdout
        outs.append(np.asarray(Image.open(out)))
    assert outs[0].shape == (30, 40, 4)
    assert np.array_equal(outs[0], outs[1])
    sample_pixels = set(map(tuple, codes.reshape(-1, 3).tolist()))
    assert set(map(tuple, outs[0][..., :3].reshape(-1, 3).tolist())) <= sample_pixels
    # The same choices as the Python API (which measures the same linear values).
    assert np.array_equal(outs[0][..., :3], mr.synthesize(codes, (40, 30), window=7, seed=5))


def test_render_resolve_filter(tmp_path):
    box = tmp_path / "box.png"
    lanczos = tmp_path / "lanczos.png"
    size = ("--size", "64x36", "--spp", "4", "--quiet")
    assert run("render", "-o", str(box), *size).returncode == 0
    r = run("render", "-o", str(lanczos), *size, "--resolve", "lanczos3")
    assert r.returncode == 0, r.stderr
    a = np.asarray(Image.open(box)).astype(int)
    b = np.asarray(Image.open(lanczos)).astype(int)
    assert a.shape == b.shape and np.abs(a - b).max() > 10


@pytest.mark.parametrize("args, status, message", [
    (["resize", "IN", "-o", "o.png", "--size", "0x4"], 2, "--size: 0x4 is out of range"),
    (["resize", "IN", "-o", "o.png", "--size", "4"], 2, "--size: expected WxH"),
    (["resize", "IN", "-o", "o.png", "--size", "4x4", "--filter", "gauss"], 2, "filter: unknown name 'gauss'"),
    (["resize", "IN", "-o", "o.png"], 2, "resize: missing --size"),
    (["resize", "-o", "o.png", "--size", "4x4"], 2, "resize: missing the input image"),
    (["resize", "missing.png", "-o", "o.png", "--size", "4x4"], 1, "missing.png"),
    (["synthesize", "IN", "-o", "o.png", "--size", "8x8", "--window", "4"], 2, "--window: expected an odd size"),
    (["synthesize", "IN", "-o", "o.png", "--size", "8x8", "--window", "31"], 2, "--window 31: larger than the sample"),
    (["synthesize", "IN", "-o", "o.png", "--size", "8x8", "--seed", "-3"], 2, "--seed: expected an integer from 0 to 18446744073709551615, got '-3'"),
    (["synthesize", "IN", "-o", "o.png", "--size", "8x8", "--epsilon", "-1"], 2, "--epsilon"),
    (["synthesize", "IN", "-o", "o.png", "--size", "9000x8"], 2, "--size: 9000x8 is out of range"),
    (["synthesize", "IN", "-o", "o.png", "--size", "8x8", "--bogus"], 2, "synthesize: unknown option '--bogus'"),
    (["render", "-o", "o.png", "--resolve", "gauss"], 2, "resolve filter: unknown name 'gauss'"),
])
def test_bad_input_names_it(tmp_path, args, status, message):
    src = write_png(tmp_path / "in.png", np.zeros((20, 20, 3), np.uint8))
    args = [src if a == "IN" else str(tmp_path / a) if a.endswith(".png") and a != "IN" else a for a in args]
    r = run(*args)
    assert r.returncode == status, (r.stdout, r.stderr)
    assert message in r.stderr


def test_a_corrupt_sample_is_an_error_naming_the_file(tmp_path):
    bad = tmp_path / "bad.png"
    bad.write_bytes(b"\x89PNG\r\n\x1a\nnot really")
    r = run("synthesize", str(bad), "-o", str(tmp_path / "o.png"), "--size", "8x8", "--window", "3")
    assert r.returncode == 1 and "bad.png" in r.stderr
