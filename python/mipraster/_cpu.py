"""What the compiled modules need of the CPU, checked before they load.

A build compiled for x86-64-v3 (CMake's ``MIPRASTER_X86_LEVEL``, by default the level of the machine
that builds) would stop on an illegal instruction on an older CPU; ``import mipraster`` raises an
ImportError that says so instead.
"""
from __future__ import annotations

from typing import Iterable, List, Optional

# x86-64-v3 by the names Linux gives in /proc/cpuinfo (LZCNT is "abm" on older kernels).
_V3_FLAGS = ("avx", "avx2", "bmi1", "bmi2", "f16c", "fma", "movbe")


def missing_features(level: str, flags: Iterable[str]) -> List[str]:
    """The features of x86-64 level ``level`` ("baseline" or "v3") that ``flags`` lack."""
    if level == "baseline":
        return []
    if level != "v3":
        raise ValueError(f"unknown x86-64 level {level!r}; expected 'baseline' or 'v3'")
    have = set(flags)
    missing = [f for f in _V3_FLAGS if f not in have]
    if not ({"lzcnt", "abm"} & have):
        missing.append("lzcnt")
    return missing


def cpu_flags(cpuinfo: str = "/proc/cpuinfo") -> Optional[List[str]]:
    """The CPU's feature flags from ``cpuinfo``, or None where there is no such file (not Linux)."""
    try:
        with open(cpuinfo) as f:
            for line in f:
                if line.startswith("flags"):
                    return line.split(":", 1)[1].split()
    except OSError:
        return None
    return None


def check_cpu(level: str, cpuinfo: str = "/proc/cpuinfo") -> None:
    """Raise ImportError when this CPU cannot run modules compiled for ``level``."""
    flags = cpu_flags(cpuinfo)
    if flags is None:
        return  # nothing to read the flags from: the modules will tell, if anything
    missing = missing_features(level, flags)
    if missing:
        raise ImportError(
            f"mipraster was compiled for x86-64-{level} (AVX2), which this CPU does not have "
            f"(missing: {', '.join(missing)}); reinstall it for this machine with "
            "`pip install . -C cmake.define.MIPRASTER_X86_LEVEL=baseline`")
