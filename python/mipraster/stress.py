"""The numerical stress suite: :func:`stress` runs the twelve cases and returns one row each.

Each row says what was tried, the figure measured against an independent oracle (exact integer
coverage, a double-precision clip-space ray cast, a double texture reference), the bound it must
meet and whether it did. ``full=False`` runs the fast sizes CI uses (about a minute on 2 cores);
``full=True`` the issue's sizes (10^7 samples and more, a 16384^2 texture: minutes and ~6 GiB).
The same cases run as C++ tests (``test_stress``) and from the command line (``mipraster stress``).
"""
from __future__ import annotations

from typing import List

from . import _core

__all__ = ["stress", "StressRow", "format_stress_report"]

#: One row of the report (``mipraster._core.StressRow``): number, name, tried, figure, bound, passed, details.
StressRow = _core.StressRow


def stress(full: bool = False) -> List[StressRow]:
    """Runs the stress suite and returns its rows (the case number, what was tried, the measured
    figure, the bound, ``passed``, per-setting ``details``). ``full`` selects the issue's sizes."""
    if not isinstance(full, bool):
        raise TypeError(f"full: expected a bool, got {type(full).__name__}")
    return _core.run_stress_suite("full" if full else "fast")


def format_stress_report(rows: List[StressRow], details: bool = False) -> str:
    """The rows as plain text (PASS/FAIL, case, tried, figure, bound; ``details`` adds the measurements)."""
    return _core.format_stress_report(list(rows), details)
