"""Image comparison with thresholds: :func:`compare` and its :class:`CompareReport`.

The comparison is OpenImageIO ``idiff``'s: every value (each channel of each pixel) is compared;
a value *fails* when ``|actual - expected| > fail_threshold``; the comparison fails when more than
``fail_fraction`` of the values fail, or when any value differs by more than
``hard_fail_threshold``. A NaN in either image always fails. The work is done in C++
(``mipraster._core.compare_images``); golden-image tests build on it (:mod:`mipraster.testing`).
"""
from __future__ import annotations

import math
import os
from typing import Any, Union

import numpy as np

from . import _checks, _core

__all__ = ["compare", "CompareReport"]

#: The report :func:`compare` returns (``mipraster._core.CompareReport``).
CompareReport = _core.CompareReport

ImageLike = Union[np.ndarray, str, "os.PathLike[str]"]


def _image(value: Any, name: str) -> np.ndarray:
    """A path (read as linear float) or a float array of shape (H, W) or (H, W, C), as float32."""
    if isinstance(value, (str, bytes, os.PathLike)):
        from .image import read_image

        return read_image(value)
    a = _checks.real_array(
        value, name, integers=False,
        hint="; expected floating-point values or a path (8-bit data: convert to float first, e.g. codes / 255)",
    )
    _checks.check_shape(a, name, (None, None), (None, None, None), letters=("H", "W", "C"))
    with np.errstate(over="ignore", invalid="ignore"):  # float64 beyond float32 becomes inf: it fails
        return np.ascontiguousarray(a, dtype=np.float32)


def _threshold(value: Any, name: str) -> float:
    v = _checks.real(value, name)
    if math.isnan(v) or v < 0:
        raise ValueError(f"{name}: expected a number >= 0, got {v!r}")
    return v


def _fraction(value: Any, name: str) -> float:
    v = _checks.real(value, name)
    if not 0 <= v <= 1:
        raise ValueError(f"{name}: expected a fraction in [0, 1], got {v!r}")
    return v


def compare(actual: ImageLike, expected: ImageLike, fail_threshold: float = 1 / 255, fail_fraction: float = 0.0,
            hard_fail_threshold: float = 1.0) -> CompareReport:
    """Compares two images value by value and returns a :class:`CompareReport`.

    Args:
        actual, expected: ``(H, W)`` or ``(H, W, C)`` arrays of floating-point values (compared as
            float32), or paths of image files, read with :func:`mipraster.read_image` (linear float,
            premultiplied RGBA, ``(H, W, 4)``: 8-bit PNGs are decoded from sRGB first).
        fail_threshold: a value fails when it differs by more than this (strictly).
        fail_fraction: the comparison fails when more than this fraction of the values fail
            (strictly; 0 = none may fail), in [0, 1].
        hard_fail_threshold: the comparison fails when any value differs by more than this
            (strictly), however few such values there are; ``math.inf`` disables it.

    Returns:
        The report: ``passed`` (the verdict), ``max_abs_error``, ``mean_abs_error``, ``rmse``,
        ``psnr`` (dB, peak 1.0, inf when identical), ``failing_values``, ``failing_fraction``,
        ``hard_failing_values``, ``nan_values``, the worst value's ``worst_x`` / ``worst_y`` /
        ``worst_channel`` (−1 when nothing differs) and ``values_compared``; ``str(report)`` is a
        short human-readable report. Use ``report.passed``: ``bool(report)`` raises TypeError.

    A NaN in either image fails (and fails hard) whatever the thresholds, even in both at the
    same place; equal infinities match.

    Raises:
        TypeError: an image that is neither a float array nor a path, or a threshold that is not a
            number.
        ValueError: a wrong shape, images of different sizes (the message names both), a negative
            or NaN threshold, or ``fail_fraction`` outside [0, 1].
        OSError: an image file that cannot be read (FileNotFoundError when it does not exist).
    """
    settings = _core.CompareSettings(
        fail_threshold=_threshold(fail_threshold, "fail_threshold"),
        fail_fraction=_fraction(fail_fraction, "fail_fraction"),
        hard_fail_threshold=_threshold(hard_fail_threshold, "hard_fail_threshold"),
    )
    a = _image(actual, "actual")
    b = _image(expected, "expected")
    return _core.compare_images(a, b, settings)  # ValueError naming both sizes when they differ
