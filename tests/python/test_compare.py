"""mipraster.compare: metrics against numpy, idiff threshold semantics, NaN, paths, and every error."""
import math

import numpy as np
import pytest

import mipraster as mr


def random_pair(shape=(6, 5, 4), seed=3, scale=0.05):
    rng = np.random.default_rng(seed)
    expected = rng.uniform(0, 1, shape).astype(np.float32)
    actual = (expected + rng.normal(0, scale, shape)).astype(np.float32)
    return actual, expected


def test_metrics_match_numpy():
    actual, expected = random_pair()
    r = mr.compare(actual, expected, fail_threshold=0.05, fail_fraction=0.5, hard_fail_threshold=1.0)
    d = np.abs(actual.astype(np.float64) - expected)
    assert (r.width, r.height, r.channels, r.values_compared) == (5, 6, 4, d.size)
    assert r.max_abs_error == d.max()
    assert r.mean_abs_error == pytest.approx(d.mean(), rel=1e-12)
    assert r.rmse == pytest.approx(np.sqrt((d ** 2).mean()), rel=1e-12)
    assert r.psnr == pytest.approx(10 * np.log10(1 / (d ** 2).mean()), rel=1e-12)
    assert r.failing_values == int((d > 0.05).sum())
    assert r.failing_fraction == pytest.approx((d > 0.05).mean())
    y, x, c = np.unravel_index(np.argmax(d), d.shape)
    assert (r.worst_x, r.worst_y, r.worst_channel) == (x, y, c)
    assert (r.worst_actual, r.worst_expected) == (actual[y, x, c], expected[y, x, c])
    assert r.passed == (r.failing_fraction <= 0.5)
    assert r.settings.fail_threshold == 0.05 and r.settings.fail_fraction == 0.5


def test_identical_images():
    a = np.linspace(0, 1, 24, dtype=np.float32).reshape(2, 3, 4)
    r = mr.compare(a, a.copy())
    assert r.passed and r.max_abs_error == 0 and r.psnr == math.inf
    assert (r.worst_x, r.worst_y, r.worst_channel) == (-1, -1, -1)
    assert str(r).startswith("PASS\n") and "PSNR inf dB" in str(r)
    assert repr(r) == "CompareReport(passed=True, 3x2x4, failing_values=0, max_abs_error=0.0)"


def test_thresholds_are_strict_at_the_boundaries():
    expected = np.zeros((2, 2), np.float32)
    actual = np.array([[0.25, 0], [0, 0]], np.float32)  # one value of four, off by exactly 0.25
    assert mr.compare(actual, expected, fail_threshold=0.25).passed
    assert not mr.compare(actual, expected, fail_threshold=np.nextafter(0.25, 0)).passed
    assert mr.compare(actual, expected, fail_threshold=0.1, fail_fraction=0.25).passed
    assert not mr.compare(actual, expected, fail_threshold=0.1, fail_fraction=np.nextafter(0.25, 0)).passed
    assert mr.compare(actual, expected, fail_threshold=0, fail_fraction=1, hard_fail_threshold=0.25).passed
    r = mr.compare(actual, expected, fail_threshold=0, fail_fraction=1, hard_fail_threshold=0.2)
    assert not r.passed and r.hard_failing_values == 1 and "hard limit" in str(r)


def test_defaults_are_one_code_no_fraction_hard_one():
    expected = np.full((4, 4, 3), 0.5, np.float32)
    assert mr.compare(expected + np.float32(0.5 / 255), expected).passed
    assert not mr.compare(expected + np.float32(1.5 / 255), expected).passed  # a single failing value fails


@pytest.mark.parametrize("where", ["actual", "expected", "both"])
def test_nan_never_passes(where):
    a = np.zeros((3, 3, 4), np.float32)
    b = a.copy()
    if where in ("actual", "both"):
        a[1, 2, 0] = np.nan
    if where in ("expected", "both"):
        b[1, 2, 0] = np.nan
    r = mr.compare(a, b, fail_threshold=math.inf, fail_fraction=1.0, hard_fail_threshold=math.inf)
    assert not r.passed
    assert (r.nan_values, r.failing_values, r.hard_failing_values) == (1, 1, 1)
    assert r.max_abs_error == math.inf and r.psnr == -math.inf
    assert (r.worst_x, r.worst_y, r.worst_channel) == (2, 1, 0)
    assert "1 NaN value" in str(r)


def test_bool_is_refused_so_that_assert_report_cannot_pass_by_mistake():
    r = mr.compare(np.zeros((2, 2)), np.ones((2, 2)))
    with pytest.raises(TypeError, match="use report.passed"):
        assert r
    assert r.passed is False


def test_float64_and_2d_inputs():
    a = np.zeros((3, 4))  # float64, (H, W)
    r = mr.compare(a, a[..., None] + 1e-9)  # (H, W) and (H, W, 1) are both one channel
    assert r.passed and r.channels == 1
    big = np.array([[1e300]])  # beyond float32: becomes inf and fails
    assert not mr.compare(big, np.zeros((1, 1))).passed


def test_paths_are_read_as_linear_float(tmp_path):
    image = np.zeros((4, 5, 4), np.float32)
    image[..., :3] = mr.srgb_to_linear(np.float32(100 / 255))
    image[..., 3] = 1
    mr.write_image(tmp_path / "a.png", image)
    r = mr.compare(tmp_path / "a.png", image, fail_threshold=1e-6)
    assert r.passed and r.max_abs_error < 1e-6
    assert mr.compare(str(tmp_path / "a.png"), tmp_path / "a.png").max_abs_error == 0
    with pytest.raises(FileNotFoundError):
        mr.compare(tmp_path / "missing.png", image)


def test_size_mismatch_names_both_sizes():
    with pytest.raises(ValueError, match=r"actual is 5x4 with 4 channels, expected is 5x3 with 4 channels"):
        mr.compare(np.zeros((4, 5, 4)), np.zeros((3, 5, 4)))
    with pytest.raises(ValueError, match=r"actual is 2x2 with 3 channels, expected is 2x2 with 4 channels"):
        mr.compare(np.zeros((2, 2, 3)), np.zeros((2, 2, 4)))


@pytest.mark.parametrize("kwargs, error, match", [
    (dict(actual=np.zeros((2, 2), np.uint8)), TypeError, "actual: expected floating-point numbers, got dtype uint8"),
    (dict(expected=np.array(["a"])), TypeError, "expected: expected floating-point numbers"),
    (dict(actual=np.zeros(4)), ValueError, r"actual: expected shape \(H, W\) or \(H, W, C\), got \(4,\)"),
    (dict(expected=np.zeros((1, 2, 3, 4))), ValueError, "expected: expected shape"),
    (dict(fail_threshold=-0.1), ValueError, "fail_threshold: expected a number >= 0, got -0.1"),
    (dict(fail_threshold=math.nan), ValueError, "fail_threshold"),
    (dict(fail_threshold="0.1"), TypeError, "fail_threshold: expected a number"),
    (dict(hard_fail_threshold=-1), ValueError, "hard_fail_threshold"),
    (dict(fail_fraction=1.5), ValueError, r"fail_fraction: expected a fraction in \[0, 1\], got 1.5"),
    (dict(fail_fraction=True), TypeError, "fail_fraction"),
])
def test_bad_arguments(kwargs, error, match):
    args = dict(actual=np.zeros((2, 2)), expected=np.zeros((2, 2)))
    args.update(kwargs)
    with pytest.raises(error, match=match):
        mr.compare(**args)


def test_core_settings_validate_and_print():
    s = mr._core.CompareSettings()
    assert (s.fail_threshold, s.fail_fraction, s.hard_fail_threshold) == (1 / 255, 0.0, 1.0)
    assert repr(s) == "CompareSettings(fail_threshold=0.00392157, fail_fraction=0, hard_fail_threshold=1)"
    s.fail_fraction = 2
    with pytest.raises(ValueError, match="CompareSettings::fail_fraction"):
        s.validate()
    with pytest.raises(ValueError, match="CompareSettings::fail_fraction"):
        mr._core.compare_images(np.zeros((1, 1), np.float32), np.zeros((1, 1), np.float32), s)
