"""Argument checks shared by the Python layer.

Every check raises before anything reaches C++: ``TypeError`` for a value of the wrong kind
(a string, a bool, an object array, ...), ``ValueError`` for the wrong shape, a non-finite
number or a value out of range. Messages name the argument, what was expected and what was got.
"""
from __future__ import annotations

import operator
from typing import Any, Mapping, Optional, Sequence, Tuple, TypeVar

import numpy as np

E = TypeVar("E")

_KIND_NAMES = {
    "b": "bool",
    "c": "complex",
    "O": "object",
    "U": "str",
    "S": "bytes",
    "V": "void/structured",
    "M": "datetime64",
    "m": "timedelta64",
}


def as_array(value: Any, name: str) -> np.ndarray:
    """``np.asarray(value)`` with a message naming the argument when it is not an array at all."""
    try:
        return np.asarray(value)
    except (ValueError, TypeError) as e:  # e.g. a ragged nested list
        raise ValueError(f"{name}: cannot be read as a rectangular array ({e})") from None


def _dtype_name(a: np.ndarray) -> str:
    kind = _KIND_NAMES.get(a.dtype.kind)
    return str(a.dtype) if kind is None or kind == str(a.dtype) else f"{a.dtype} ({kind})"


def real_array(value: Any, name: str, *, integers: bool = True, hint: str = "") -> np.ndarray:
    """An array of real numbers: float, or also integer when ``integers``; TypeError otherwise."""
    a = as_array(value, name)
    if a.dtype.kind == "f" or (integers and a.dtype.kind in "iu"):
        return a
    if a.size == 0 and a.dtype.kind in "fiu":  # an empty list comes out as float64
        return a
    wanted = "float or integer numbers" if integers else "floating-point numbers"
    raise TypeError(f"{name}: expected {wanted}, got dtype {_dtype_name(a)}{hint}")


def integer_array(value: Any, name: str, *, hint: str = "") -> np.ndarray:
    """An array of integers (any integer dtype); TypeError otherwise (floats included)."""
    a = as_array(value, name)
    if a.dtype.kind in "iu":
        return a
    if a.size == 0 and a.dtype.kind == "f":  # np.asarray([]) is float64
        return a.astype(np.int64)
    raise TypeError(f"{name}: expected integers, got dtype {_dtype_name(a)}{hint}")


def _shape_text(shape: Sequence[Any]) -> str:
    parts = [str(s) for s in shape]
    return "(" + ", ".join(parts) + ("," if len(parts) == 1 else "") + ")"


def check_shape(a: np.ndarray, name: str, *expected: Tuple[Optional[int], ...],
                letters: Sequence[str] = ("N",)) -> None:
    """ValueError unless ``a.shape`` matches one of ``expected`` (None = any extent, shown in the
    message as the next of ``letters``, e.g. ("H", "W"))."""
    for shape in expected:
        if a.ndim == len(shape) and all(e is None or e == s for e, s in zip(shape, a.shape)):
            return

    def text(shape: Tuple[Optional[int], ...]) -> str:
        free = iter(letters)
        return _shape_text([next(free, "N") if e is None else e for e in shape])

    options = " or ".join(text(s) for s in expected)
    raise ValueError(f"{name}: expected shape {options}, got {_shape_text(a.shape)}")


def empty_rows(a: np.ndarray, columns: int) -> np.ndarray:
    """An empty 1-D array (``[]``) as zero rows of ``columns``."""
    return a.reshape(0, columns) if a.ndim == 1 and a.size == 0 else a


def first_nonfinite(a: np.ndarray) -> Optional[Tuple[int, ...]]:
    """The index of the first NaN or infinite element of a float array, else None."""
    if a.dtype.kind != "f":
        return None
    bad = ~np.isfinite(a)
    if not bad.any():
        return None
    return tuple(int(i) for i in np.argwhere(bad)[0])


def check_finite(a: np.ndarray, name: str) -> None:
    """ValueError naming the first NaN or infinite element (row and column for 2-D arrays)."""
    index = first_nonfinite(a)
    if index is None:
        return
    where = f"{name}[{', '.join(map(str, index))}]"
    if len(index) == 2:
        where += f" (row {index[0]}, column {index[1]})"
    raise ValueError(f"{where} is {a[index]}; expected a finite number")


FLOAT32_MAX = float(np.finfo(np.float32).max)


def check_fits_float32(a: np.ndarray, name: str) -> None:
    """ValueError naming the first finite element beyond float32's range (NaN and ±inf are left to
    the caller): converted to float32 it would become ±inf."""
    if a.dtype.kind != "f" or a.dtype.itemsize <= 4:
        return
    with np.errstate(invalid="ignore"):
        big = np.isfinite(a) & (np.abs(a) > FLOAT32_MAX)
    if big.any():
        index = tuple(int(i) for i in np.argwhere(big)[0])
        raise ValueError(f"{name}[{', '.join(map(str, index))}] = {a[index]} does not fit in float32")


def to_float32(a: np.ndarray, name: str) -> np.ndarray:
    """A C-contiguous float32 copy (or the array itself when it is one); ValueError on float32 overflow."""
    with np.errstate(over="ignore", invalid="ignore"):
        out = np.ascontiguousarray(a, dtype=np.float32)
    if a.dtype.kind == "f" and a.dtype.itemsize > 4 and not np.isfinite(out).all():
        index = tuple(int(i) for i in np.argwhere(~np.isfinite(out))[0])
        raise ValueError(f"{name}[{', '.join(map(str, index))}] = {a[index]} does not fit in float32")
    return out


def vector(value: Any, name: str, sizes: Tuple[int, ...] = (3,)) -> np.ndarray:
    """A finite real vector of one of the given lengths, as float64."""
    a = real_array(value, name)
    if a.ndim == 2 and 1 in a.shape:  # column or row vectors, e.g. OpenCV's (3, 1) tvec
        a = a.reshape(-1)
    check_shape(a, name, *[(n,) for n in sizes])
    check_finite(a, name)
    return a.astype(np.float64)


def matrix(value: Any, name: str, rows: int, columns: int) -> np.ndarray:
    """A finite real matrix of the given shape, as C-contiguous float64."""
    a = real_array(value, name)
    check_shape(a, name, (rows, columns))
    check_finite(a, name)
    return np.ascontiguousarray(a, dtype=np.float64)


def rgba(value: Any, name: str) -> Tuple[float, float, float, float]:
    """A colour of 3 (alpha 1) or 4 finite components that fit in float32 (the renderer's colours)."""
    if type(value) in (tuple, list) and len(value) in (3, 4) and all(
            type(c) is float and abs(c) <= FLOAT32_MAX for c in value):  # (NaN fails the comparison)
        return (value[0], value[1], value[2], value[3] if len(value) == 4 else 1.0)  # (a render's common case, fast)
    a = vector(value, name, (3, 4))
    check_fits_float32(a, name)
    if a.shape[0] == 3:
        a = np.append(a, 1.0)
    return (float(a[0]), float(a[1]), float(a[2]), float(a[3]))


def integer(value: Any, name: str) -> int:
    """A Python int from an int or numpy integer; TypeError for bool, float, str, ..."""
    if isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name}: expected an integer, got {type(value).__name__} {value!r}")
    try:
        return operator.index(value)
    except TypeError:
        raise TypeError(f"{name}: expected an integer, got {type(value).__name__} {value!r}") from None


def real(value: Any, name: str) -> float:
    """A Python float from a real number; TypeError for bool, str, ..."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TypeError(f"{name}: expected a number, got {type(value).__name__} {value!r}")
    return float(value)


def unit_or_none(value: Any, name: str) -> Optional[float]:
    """None, or a real number in [0, 1] as a Python float; TypeError for bool, str, ..., ValueError
    for NaN or a number outside [0, 1]."""
    if value is None:
        return None
    v = real(value, name)
    if not 0.0 <= v <= 1.0:  # (NaN fails too)
        raise ValueError(f"{name}: expected a number in [0, 1] or None, got {v!r}")
    return v


def flag(value: Any, name: str) -> bool:
    """A bool (Python or numpy); TypeError otherwise, so that e.g. the string 'false' is refused."""
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name}: expected True or False, got {type(value).__name__} {value!r}")
    return bool(value)


def choice(value: Any, name: str, options: Mapping[str, E]) -> E:
    """The option named ``value``; ValueError listing the accepted names otherwise."""
    if isinstance(value, str) and value in options:
        return options[value]
    accepted = ", ".join(repr(k) for k in options)
    if not isinstance(value, str):
        raise TypeError(f"{name}: expected one of {accepted}, got {type(value).__name__} {value!r}")
    raise ValueError(f"{name}: unknown value {value!r}; expected one of {accepted}")
