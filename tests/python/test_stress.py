"""The stress suite from Python (``mipraster.stress``) and the command line (``mipraster stress``).

The C++ test ``test_stress`` asserts each case; here the Python entry points must return the same
rows, every case 1..12 present and passing in the fast sizes, and bad arguments must raise.
"""
import json

import pytest

import mipraster as mr
from test_cli import run


@pytest.fixture(scope="module")
def rows():
    return mr.stress()


def test_every_case_is_reported_and_passes(rows):
    assert sorted({r.number for r in rows}) == list(range(1, 13))
    for r in rows:
        assert r.figure and r.bound and r.tried, r
        assert r.passed, mr.format_stress_report([r], details=True)


def test_rows_carry_measurements_and_print(rows):
    watertight = next(r for r in rows if r.number == 1)
    assert "cracks 0" in watertight.figure
    assert any("S=16" in d for d in watertight.details)
    assert "PASS" in repr(watertight)
    text = mr.format_stress_report(rows)
    assert text.count("PASS ") == len(rows)
    assert json.loads(watertight.to_json())["number"] == 1


def test_bad_arguments_raise():
    with pytest.raises(TypeError, match="full"):
        mr.stress(full="yes")
    with pytest.raises(ValueError, match="fast"):
        mr._core.run_stress_suite("huge")


def test_command_prints_rows_and_writes_json(tmp_path):
    out = tmp_path / "stress.json"
    p = run("stress", "--json", str(out))
    assert p.returncode == 0, p.stdout + p.stderr
    assert "14 of 14 rows pass" in p.stdout
    data = json.loads(out.read_text())
    assert [r["number"] for r in data] == sorted(r["number"] for r in data)
    assert all(r["pass"] for r in data)


def test_command_refuses_unknown_options_and_unwritable_json(tmp_path):
    p = run("stress", "--fast")
    assert p.returncode == 2 and "unknown option '--fast'" in p.stderr
    p = run("stress", "--json", str(tmp_path / "missing" / "x.json"))
    assert p.returncode == 1 and "cannot write" in p.stderr
