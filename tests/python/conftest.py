"""Shared pytest configuration: the ``--update-goldens`` option and its ``update_goldens`` fixture.

Golden-image tests (test_golden.py) compare renders with the PNGs in tests/golden/ and rewrite them
only when pytest runs with ``--update-goldens``; see tests/golden/README.md.
"""
import pytest


def pytest_addoption(parser):
    parser.addoption(
        "--update-goldens", action="store_true", default=False,
        help="rewrite the golden images (tests/golden/*.png) from the current renders instead of comparing "
             "with them; look at the new images before committing them",
    )


@pytest.fixture
def update_goldens(request):
    """True when pytest runs with --update-goldens: golden tests write their golden instead of comparing."""
    return bool(request.config.getoption("--update-goldens"))
