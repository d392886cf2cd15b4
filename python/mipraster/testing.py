"""Golden-image testing: :func:`assert_matches_golden` compares a render with a reference PNG.

Use it from pytest::

    from mipraster.testing import assert_matches_golden

    def test_triangle(update_goldens):            # the fixture reads pytest's --update-goldens
        result = mr.render(scene, camera, 96, 64, spp=4, aa="msaa")
        assert_matches_golden(result.color, GOLDEN_DIR / "triangle.png", update=update_goldens)

Goldens are sRGB 8-bit PNGs (what :func:`mipraster.write_image` writes). They change only when
the test runs with ``update=True`` (``pytest --update-goldens`` in this project's test suite); a
missing golden is a failure that says how to make it, never a skip. On a mismatch the actual,
expected and difference images are written for inspection (see :func:`assert_matches_golden`).

This module is not imported by ``import mipraster``; it needs no pytest itself (failures raise
``AssertionError``).
"""
from __future__ import annotations

import os
import pathlib
import shutil
from typing import Any, Optional, Tuple, Union

import numpy as np

from . import _checks
from .compare import CompareReport, _fraction, _threshold, compare
from .image import read_image, to_srgb8, write_image
from .render import RenderResult

__all__ = [
    "assert_matches_golden",
    "golden_output_paths",
    "GOLDEN_FAIL_THRESHOLD",
    "GOLDEN_FAIL_FRACTION",
    "GOLDEN_HARD_FAIL_THRESHOLD",
    "DIFF_GAIN",
    "OUT_DIR_ENV",
]

#: Default thresholds of :func:`assert_matches_golden`, in sRGB8 codes / 255.
GOLDEN_FAIL_THRESHOLD = 2 / 255
GOLDEN_FAIL_FRACTION = 0.002
GOLDEN_HARD_FAIL_THRESHOLD = 0.25
#: The diff image shows |actual − expected| (sRGB8 codes) multiplied by this.
DIFF_GAIN = 8
#: Environment variable naming the directory the failure images go to (default: next to the golden).
OUT_DIR_ENV = "MIPRASTER_GOLDEN_OUT"

# Values compared are multiples of 1/255 stored as float32, so a difference of exactly n codes can
# come out a few 1e-8 above n/255. Thresholds are applied with this much slack (well under a code)
# so that "fail_threshold = 2/255" means "more than 2 codes" exactly.
_CODE_SLACK = 1e-6

PathLike = Union[str, "os.PathLike[str]"]


def golden_output_paths(golden_path: PathLike, out_dir: Optional[PathLike] = None) -> Tuple[pathlib.Path, ...]:
    """Where :func:`assert_matches_golden` writes ``(actual, expected, diff)`` for ``golden_path``.

    ``<name>.actual.png``, ``<name>.expected.png`` and ``<name>.diff.png`` (``<name>`` = the
    golden's file name without ``.png``) in ``out_dir`` if given, else in the directory named by
    the environment variable ``MIPRASTER_GOLDEN_OUT`` if set, else next to the golden.
    """
    golden = pathlib.Path(os.fspath(golden_path))
    if out_dir is None:
        env = os.environ.get(OUT_DIR_ENV)
        out = pathlib.Path(env) if env else golden.parent
    else:
        out = pathlib.Path(os.fspath(out_dir))
    stem = golden.name[:-4] if golden.name.lower().endswith(".png") else golden.name
    return tuple(out / f"{stem}.{kind}.png" for kind in ("actual", "expected", "diff"))


def _linear_image(actual: Any) -> np.ndarray:
    if isinstance(actual, RenderResult):
        actual = actual.color
    a = _checks.real_array(actual, "actual", integers=False,
                           hint="; expected a render's linear colour (RenderResult.color)")
    _checks.check_shape(a, "actual", (None, None, 4), (None, None, 3), letters=("H", "W"))
    return a


def _codes(srgb8: np.ndarray) -> np.ndarray:
    return srgb8.astype(np.float32) / np.float32(255)


def _write_diff(path: pathlib.Path, actual8: np.ndarray, expected8: np.ndarray) -> None:
    """An opaque RGB image whose bytes are min(255, DIFF_GAIN · |Δ|) per colour channel, where a
    difference in alpha shows in all three channels."""
    delta = np.abs(actual8.astype(np.int32) - expected8.astype(np.int32))
    shown = np.maximum(delta[..., :3], delta[..., 3:4])
    encoded = np.minimum(255, DIFF_GAIN * shown).astype(np.float32) / np.float32(255)
    from . import _core

    write_image(path, _core.srgb_to_linear(encoded).astype(np.float32))  # PNG bytes = the values above


def _remove_stale(paths: Tuple[pathlib.Path, ...]) -> None:
    for p in paths:
        try:
            p.unlink()
        except FileNotFoundError:
            pass


def _update_hint() -> str:
    test = os.environ.get("PYTEST_CURRENT_TEST", "").rsplit(" ", 1)[0]
    where = f"python3 -m pytest '{test}' --update-goldens" if test else "pytest --update-goldens"
    return (f"run `{where}` (or pass update=True) to write it, look at the image, then commit it")


def _holds(golden: pathlib.Path, actual8: np.ndarray) -> bool:
    """Whether the golden file exists, is readable and holds exactly these sRGB8 bytes."""
    if not golden.is_file():
        return False
    try:
        return bool(np.array_equal(to_srgb8(read_image(golden)), actual8))
    except OSError:
        return False


def assert_matches_golden(
    actual: Any,
    golden_path: PathLike,
    *,
    update: bool = False,
    out_dir: Optional[PathLike] = None,
    fail_threshold: float = GOLDEN_FAIL_THRESHOLD,
    fail_fraction: float = GOLDEN_FAIL_FRACTION,
    hard_fail_threshold: float = GOLDEN_HARD_FAIL_THRESHOLD,
) -> Optional[CompareReport]:
    """Asserts that a render matches a golden PNG; with ``update=True``, (re)writes the golden instead.

    **What is compared:** the golden is an sRGB 8-bit PNG, so the comparison happens in sRGB8 code
    space: ``actual`` is encoded with :func:`mipraster.to_srgb8` (straight alpha, sRGB colour,
    linear alpha: the bytes a PNG of it would hold), the golden is read back to the same bytes
    (``to_srgb8(read_image(golden))``, exact for every pixel with alpha > 0; fully transparent
    pixels are (0, 0, 0, 0) on both sides), and both are compared as ``bytes / 255`` floats with
    :func:`mipraster.compare`. Every channel counts, alpha included. Thresholds are in those units:
    the default ``fail_threshold = 2/255`` lets a value be off by 2 codes (applied with 1e-6 of
    slack, so that exactly 2 codes passes despite float rounding).

    Args:
        actual: the render's linear premultiplied colour, ``(H, W, 4)`` (or linear RGB
            ``(H, W, 3)``) float, e.g. ``RenderResult.color``; a :class:`RenderResult` is accepted.
        golden_path: the golden PNG.
        update: write ``actual`` as the golden (creating its directory) instead of comparing. An
            existing golden that already holds exactly these bytes is left untouched, so repeated
            updates do not rewrite files. Returns None.
        out_dir: where the failure images go; default: the directory in the environment variable
            ``MIPRASTER_GOLDEN_OUT`` if set, else the golden's directory (see
            :func:`golden_output_paths`).
        fail_threshold: a value fails when it differs by more than this (default 2/255).
        fail_fraction: the test fails when more than this fraction of the values fail (default 0.002).
        hard_fail_threshold: the test fails when any value differs by more than this (default 0.25,
            64 codes).

    Returns:
        The :class:`CompareReport` when the render matches (None after an update).

    Raises:
        AssertionError: the render does not match (the message holds the report and the paths of
            ``<name>.actual.png``, ``<name>.expected.png`` and ``<name>.diff.png``: the diff shows
            ``DIFF_GAIN`` (8) × |Δ| in codes, clipped to 255, alpha differences in every channel),
            the sizes differ (actual and expected are written), or the golden does not exist and
            ``update`` is false (the actual image is written; the message says how to create the
            golden). On success, failure images left by an earlier run are removed.
        TypeError, ValueError: bad arguments (see :func:`mipraster.compare`).
    """
    a = _linear_image(actual)
    update = _checks.flag(update, "update")
    golden = pathlib.Path(os.fspath(golden_path))
    # validated before any file is touched
    fail_threshold = _threshold(fail_threshold, "fail_threshold")
    fail_fraction = _fraction(fail_fraction, "fail_fraction")
    hard_fail_threshold = _threshold(hard_fail_threshold, "hard_fail_threshold")
    actual8 = to_srgb8(a)
    paths = golden_output_paths(golden, out_dir)
    actual_path, expected_path, diff_path = paths

    if update:
        if not _holds(golden, actual8):  # rewrite only a changed, missing or unreadable golden
            golden.parent.mkdir(parents=True, exist_ok=True)
            write_image(golden, a)
        _remove_stale(paths)
        return None

    if not golden.exists():
        actual_path.parent.mkdir(parents=True, exist_ok=True)
        write_image(actual_path, a)
        raise AssertionError(
            f"golden image {golden} does not exist; {_update_hint()}.\n"
            f"  this render: {actual_path}")

    expected8 = to_srgb8(read_image(golden))
    if expected8.shape != actual8.shape:
        actual_path.parent.mkdir(parents=True, exist_ok=True)
        write_image(actual_path, a)
        shutil.copyfile(golden, expected_path)
        raise AssertionError(
            f"render does not match golden {golden}: the sizes differ (actual {actual8.shape[1]}x{actual8.shape[0]}, "
            f"golden {expected8.shape[1]}x{expected8.shape[0]}); no diff image.\n"
            f"  actual:   {actual_path}\n  expected: {expected_path}\n"
            f"  if the change is intended: {_update_hint()}")

    report = compare(
        _codes(actual8), _codes(expected8),
        fail_threshold=fail_threshold + _CODE_SLACK,
        fail_fraction=fail_fraction,
        hard_fail_threshold=hard_fail_threshold + _CODE_SLACK,
    )
    if report.passed:
        _remove_stale(paths)
        return report

    actual_path.parent.mkdir(parents=True, exist_ok=True)
    write_image(actual_path, a)
    shutil.copyfile(golden, expected_path)
    _write_diff(diff_path, actual8, expected8)
    raise AssertionError(
        f"render does not match golden {golden} (compared in sRGB8 codes / 255; thresholds as given: "
        f"fail_threshold={fail_threshold:.6g}, fail_fraction={fail_fraction:.6g}, "
        f"hard_fail_threshold={hard_fail_threshold:.6g}):\n{report}\n"
        f"  actual:   {actual_path}\n  expected: {expected_path}\n  diff (x{DIFF_GAIN}): {diff_path}\n"
        f"  if the change is intended: {_update_hint()}")
