"""mipraster.resample: identity, exact ramps, weights summing to 1, linear-light filtering of sRGB
codes, no aliasing when shrinking a zone plate (measured with an FFT against point sampling), the
render's resolve filters, and the errors for bad input."""
import numpy as np
import pytest

import mipraster as mr
from mipraster import _core

FILTERS = ("box", "tent", "mitchell", "catmull-rom", "lanczos3")


def random_image(h, w, c, seed):
    return np.random.default_rng(seed).random((h, w, c), dtype=np.float32)


@pytest.mark.parametrize("filter", FILTERS)
def test_the_same_size_returns_the_input(filter):
    a = random_image(9, 14, 4, 1)
    assert np.array_equal(mr.resample(a, (14, 9), filter=filter), a)
    codes = (random_image(9, 14, 3, 2) * 255).astype(np.uint8)
    out = mr.resample(codes, (14, 9), filter=filter)
    assert out.dtype == np.uint8 and np.array_equal(out, codes)


@pytest.mark.parametrize("size", [(45, 33), (80, 61), (10, 8), (5, 4)])  # magnify, and reduce by 2 and 4
def test_tent_reproduces_a_linear_ramp_exactly(size):
    h, w = 16, 20
    y, x = np.mgrid[0:h, 0:w] + 0.5
    ramp = np.stack([0.02 * x + 0.01 * y + 0.1, -0.015 * x + 0.03 * y + 0.5], axis=-1).astype(np.float32)
    out = mr.resample(ramp, size, filter="tent")
    sx, sy = w / size[0], h / size[1]
    j, i = np.mgrid[0:size[1], 0:size[0]]
    px, py = (i + 0.5) * sx, (j + 0.5) * sy  # where each output centre lands in the input
    reach_x, reach_y = max(1.0, sx), max(1.0, sy)
    inside = (px - reach_x >= 0.5) & (px + reach_x <= w - 0.5) & (py - reach_y >= 0.5) & (py + reach_y <= h - 0.5)
    assert inside.sum() >= 0.25 * inside.size  # enough interior pixels to mean something
    expected = np.stack([0.02 * px + 0.01 * py + 0.1, -0.015 * px + 0.03 * py + 0.5], axis=-1)
    assert np.abs(out - expected)[inside].max() < 2e-6


@pytest.mark.parametrize("filter", FILTERS)
def test_each_filters_weights_sum_to_one(filter):
    for src, dst in [(7, 3), (64, 17), (10, 10), (5, 23), (1, 9), (300, 1)]:
        first, offset, weights, scale = _core.resample_weights(src, dst, filter)
        sums = np.add.reduceat(weights.astype(np.float64), offset[:-1])
        assert np.allclose(sums, 1.0, atol=1e-6), (filter, src, dst)
        assert scale == max(1.0, src / dst)
        taps = np.diff(offset)
        assert (first >= 0).all() and (first + taps <= src).all() and (taps >= 1).all()


def test_filtering_happens_in_linear_light():
    # A black/white sRGB8 checker shrunk to one pixel is linear 0.5: sRGB code 188, not 128.
    checker = np.array([[0, 255], [255, 0]], dtype=np.uint8)
    for filter in FILTERS:
        assert mr.resample(checker, (1, 1), filter=filter)[0, 0] == 188
    # With srgb=False the codes are linear data: the mean code.
    assert mr.resample(checker, (1, 1), filter="box", srgb=False)[0, 0] == 128
    # Straight alpha is premultiplied for the filtering: an opaque red pixel next to a transparent
    # green one gives half-transparent pure red, not a red/green mix.
    rgba = np.array([[[255, 0, 0, 255], [0, 255, 0, 0]]], dtype=np.uint8)
    assert mr.resample(rgba, (1, 1), filter="box").tolist() == [[[255, 0, 0, 128]]]


def zone_plate(n):
    """cos(π r²/n) around the centre: the local frequency r/n cycles per pixel reaches the input's
    Nyquist frequency (½) at the edges' midpoints."""
    y, x = np.mgrid[0:n, 0:n] + 0.5 - n / 2
    return (0.5 + 0.5 * np.cos(np.pi * (x * x + y * y) / n)).astype(np.float64)


def split_bands(image, cutoff):
    """The image's spectrum split by an FFT into the part with |fx| and |fy| ≤ cutoff (cycles per
    pixel) and the rest."""
    spectrum = np.fft.fft2(image)
    f = np.abs(np.fft.fftfreq(image.shape[0]))
    low_mask = (f[:, None] <= cutoff) & (f[None, :] <= cutoff)
    low = np.real(np.fft.ifft2(np.where(low_mask, spectrum, 0)))
    return low, image - low


def aliasing_ratio(downsample, image, factor):
    """Energy that the image's frequencies above the new Nyquist frequency (½ cycle per output
    pixel = 1/(2·factor) per input pixel) put into the downsampled image, over their own energy.
    Downsampling is linear, so it is the output of the high band alone; an ideal low-pass gives 0."""
    _, high = split_bands(image, 0.5 / factor)
    out = downsample(high.astype(np.float32))
    return float(np.mean(out.astype(np.float64) ** 2) / np.mean(high ** 2))


# Measured (512² zone plate 4× smaller / 510² 3× smaller): box 0.026 / 0.045, tent 0.0025 / 0.0078,
# mitchell 0.0019 / 0.0036, catmull-rom 0.0039 / 0.0075, lanczos3 0.0028 / 0.0055; point sampling
# (no filter) 1.00 / 1.01. The bounds are about 1.5× the worst of the two.
ALIASING_BOUNDS = {"box": 0.07, "tent": 0.012, "mitchell": 0.006, "catmull-rom": 0.012, "lanczos3": 0.009}
# Energy kept of the frequencies below half the new Nyquist frequency (measured: box 0.88,
# tent 0.76, mitchell 0.81, catmull-rom 0.95, lanczos3 1.02, the same for both factors).
PASSBAND_BOUNDS = {"box": 0.8, "tent": 0.7, "mitchell": 0.75, "catmull-rom": 0.9, "lanczos3": 0.95}


@pytest.mark.parametrize("factor", [4, 3])
def test_shrinking_a_zone_plate_adds_almost_no_aliasing(factor):
    n = 512 if factor == 4 else 510
    image = zone_plate(n)
    m = n // factor
    # The control: point sampling (no reconstruction filter) folds nearly all of it back.
    point = aliasing_ratio(lambda a: a[factor // 2::factor, factor // 2::factor], image, factor)
    assert point > 0.8
    for filter, bound in ALIASING_BOUNDS.items():
        ratio = aliasing_ratio(lambda a: mr.resample(a, (m, m), filter=filter), image, factor)
        assert ratio < bound, (filter, ratio)
    # ... while what the new grid holds well passes: the mean, and most of the energy below half
    # its Nyquist frequency (the sharper filters keep more).
    low, _ = split_bands(image, 0.25 / factor)
    for filter, bound in PASSBAND_BOUNDS.items():
        out = mr.resample(low.astype(np.float32), (m, m), filter=filter)
        assert abs(out.mean() - low.mean()) < 1e-3
        assert bound < np.var(out) / np.var(low) < 1.05, filter


def test_the_result_does_not_depend_on_the_thread_count():
    a = random_image(70, 90, 3, 3)
    one = mr.resample(a, (31, 140), filter="lanczos3", threads=1)
    assert np.array_equal(mr.resample(a, (31, 140), filter="lanczos3", threads=2), one)


def test_grey_and_grey_alpha_images_keep_their_shape():
    grey = random_image(12, 10, 1, 4)[..., 0]
    assert mr.resample(grey, (5, 6)).shape == (6, 5)
    ga = (random_image(12, 10, 2, 5) * 65535).astype(np.uint16)
    out = mr.resample(ga, (20, 24), filter="tent")
    assert out.shape == (24, 20, 2) and out.dtype == np.uint16


@pytest.mark.parametrize("filter", ["tent", "lanczos3"])
def test_render_resolve_filters_equal_resampling_the_sample_image(filter):
    # 16 samples on a 4x4 grid: the (4H, 4W) image of the samples, resampled to (H, W), is the
    # filtered resolve.
    scene = mr.Scene()
    scene.add(mr.Mesh([[-1, -1, 0], [1, -0.6, 0], [0.2, 1, 0]], [[0, 1, 2]], [[1, 0, 0], [0, 1, 0], [0, 0, 1]]))
    camera = mr.Camera.from_matrices(np.eye(4), np.eye(4))
    r = mr.render(scene, camera, 20, 14, spp=16, pattern="grid", keep_samples=True, resolve_filter=filter)
    h, w = 14, 20
    sample_image = np.zeros((4 * h, 4 * w, 4), np.float32)
    for s, (ox, oy) in enumerate(r.pattern):  # sample s of pixel (x, y) is image pixel (4x + a, 4y + b)
        a, b = int(ox * 4), int(oy * 4)
        sample_image[b::4, a::4] = r.samples[:, :, s]
    assert np.abs(r.color - mr.resample(sample_image, (w, h), filter=filter)).max() < 2e-6
    box = mr.render(scene, camera, 20, 14, spp=16, pattern="grid")
    assert np.abs(box.color - r.color).max() > 0.05  # the filter changes edge pixels


def test_bad_input_is_refused_with_a_message_naming_it():
    a = random_image(4, 4, 3, 6)
    with pytest.raises(TypeError, match="image: expected uint8 / uint16"):
        mr.resample(a.astype(np.int64), (2, 2))
    with pytest.raises(ValueError, match=r"image: expected shape"):
        mr.resample(np.zeros((4, 4, 5), np.float32), (2, 2))
    with pytest.raises(ValueError, match="empty"):
        mr.resample(np.zeros((0, 4, 3), np.float32), (2, 2))
    bad = a.copy()
    bad[1, 2, 0] = np.nan
    with pytest.raises(ValueError, match=r"image\[1, 2, 0\] is nan"):
        mr.resample(bad, (2, 2))
    with pytest.raises(ValueError, match="size: width 0 is out of range"):
        mr.resample(a, (0, 2))
    with pytest.raises(ValueError, match="size: height 100000 is out of range"):
        mr.resample(a, (2, 100000))
    with pytest.raises(TypeError, match="size: expected a"):
        mr.resample(a, "2x2")
    with pytest.raises(TypeError, match="width"):
        mr.resample(a, (2.5, 2))
    with pytest.raises(ValueError, match="filter: unknown value 'bicubic'"):
        mr.resample(a, (2, 2), filter="bicubic")
    with pytest.raises(ValueError, match="threads"):
        mr.resample(a, (2, 2), threads=-1)
    with pytest.raises(ValueError, match="resolve_filter"):
        mr.render(mr.Scene(), mr.Camera.from_matrices(np.eye(4), np.eye(4)), 4, 4, resolve_filter="gauss")
    with pytest.raises(ValueError, match="MiB"):  # refused before allocating
        _core.resample(a, 60000, 60000, "box")


def test_resampling_past_the_memory_limit_is_refused_before_allocating():
    # (only the fixed 8 GiB cap was checked: under a 64 MiB limit, 4096² RGB took 200 MB)
    a = random_image(4, 4, 3, 6)
    mr.set_memory_limit(64 << 20)
    try:
        with pytest.raises(mr.MemoryLimitError, match="resampling to 4096x4096"):
            mr.resample(a, (4096, 4096))
        assert mr.resample(a, (512, 512)).shape == (512, 512, 3)  # 6 MiB: under the limit
    finally:
        mr.set_memory_limit(0)
