"""The package itself: `import mipraster` loads no OpenImageIO (the _image module is imported on the
first file access), the type stubs cover the extension modules, and public names are documented."""
import ast
import inspect
import pathlib
import subprocess
import sys

import pytest

import mipraster as mr
from mipraster import _core

PACKAGE_DIR = pathlib.Path(mr.__file__).parent


def run_python(code):
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    return r.stdout.split()


def test_import_does_not_load_the_image_module_or_openimageio(tmp_path):
    out = run_python(
        "import sys, numpy as np, mipraster as mr\n"
        "maps = lambda: open('/proc/self/maps').read()\n"
        "print('mipraster._image' in sys.modules, 'libOpenImageIO' in maps(), 'mipraster/_core' in maps())\n"
        "scene, camera = mr.Scene.demo()\n"
        "result = mr.render(scene, camera, 16, 16)\n"
        "result.to_srgb8()\n"
        "print('mipraster._image' in sys.modules, 'libOpenImageIO' in maps())\n"
        f"result.save({str(tmp_path / 'x.png')!r})\n"
        "print('mipraster._image' in sys.modules, 'libOpenImageIO' in maps())\n"
    )
    # after import and a render: neither; after the first file write: both (the check can see them)
    assert out == ["False", "False", "True", "False", "False", "True", "True"]


def _stub_names(path):
    tree = ast.parse(path.read_text())
    top, members = set(), {}
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            top.add(node.name)
        elif isinstance(node, ast.AnnAssign):
            top.add(node.target.id)
        if isinstance(node, ast.ClassDef):
            members[node.name] = {
                (n.name if isinstance(n, ast.FunctionDef) else n.target.id)
                for n in node.body if isinstance(n, (ast.FunctionDef, ast.AnnAssign))
            }
    return top, members


@pytest.mark.parametrize("module_name", ["_core", "_image"])
def test_stubs_cover_the_extension_modules(module_name):
    module = __import__(f"mipraster.{module_name}", fromlist=["_"])
    top, members = _stub_names(PACKAGE_DIR / f"{module_name}.pyi")
    public = {n for n in dir(module) if not n.startswith("_")}
    assert public == top - {n for n in top if n.startswith("_")}
    for cls_name, stubbed in members.items():
        cls = getattr(module, cls_name, None)
        if cls is None or isinstance(getattr(cls, "__members__", None), dict):  # enums: values only
            if cls is not None:
                assert set(cls.__members__) <= stubbed, cls_name
            continue
        runtime = {n for n in dir(cls) if not n.startswith("_")}
        if isinstance(cls, type) and issubclass(cls, BaseException):
            runtime -= set(dir(BaseException))  # args, with_traceback, ...: the builtin's own
        assert runtime <= stubbed, (cls_name, runtime - stubbed)
    assert (PACKAGE_DIR / "py.typed").exists()


TESTS_DIR = pathlib.Path(__file__).resolve().parent
REPO_DIR = TESTS_DIR.parents[1]


def _run_typing_tool(args, cwd):
    """`python ARGS` in this interpreter and environment (so on the package this test imported)."""
    pytest.importorskip("mypy.stubtest", reason="mypy is not installed (pip install mypy; .ci/dev installs it)")
    r = subprocess.run([sys.executable] + args, cwd=cwd, capture_output=True, text=True, timeout=600)
    return r.returncode, (r.stdout + r.stderr).strip()


def test_stubs_match_the_runtime_signatures(tmp_path):
    # mypy's stubtest on the whole package (the .pyi stubs of _core and _image and the annotated
    # Python modules) through tests/python/stubtest_pybind11.py, which gives it the argument lists
    # pybind11 writes into docstrings: names, defaults, keyword-ness, properties, enum members.
    code, out = _run_typing_tool(
        [str(TESTS_DIR / "stubtest_pybind11.py"), "mipraster",
         "--allowlist", str(TESTS_DIR / "stubtest_allowlist.txt"),
         "--mypy-config-file", str(REPO_DIR / "pyproject.toml")], cwd=tmp_path)  # (its .mypy_cache there)
    assert code == 0 and "Success" in out, out


def test_the_package_type_checks(tmp_path):
    # mypy on the package's source (with the stubs and pyproject.toml's [tool.mypy])
    code, out = _run_typing_tool(["-m", "mypy", "--cache-dir", str(tmp_path / "mypy_cache"), "python/mipraster"],
                                 cwd=REPO_DIR)
    assert code == 0 and "Success" in out, out


def test_public_api_is_documented():
    assert mr.__doc__ and "import mipraster" in mr.__doc__
    for name in mr.__all__:
        obj = getattr(mr, name)
        assert inspect.getdoc(obj), name
        if inspect.isclass(obj):
            for attr, value in vars(obj).items():
                if not attr.startswith("_") and (callable(value) or isinstance(value, (property, classmethod))):
                    assert inspect.getdoc(getattr(obj, attr)), f"{name}.{attr}"
    assert _core.__doc__


def test_version():
    assert mr.__version__ == "0.1.0"


# --- the instruction set the modules were compiled for (CMake's MIPRASTER_X86_LEVEL) --------------

V3_FLAGS = "fpu sse2 avx avx2 bmi1 bmi2 f16c fma movbe abm"


def test_the_build_names_an_instruction_set_this_cpu_runs():
    from mipraster import _build_info, _cpu

    assert _build_info.X86_LEVEL in ("baseline", "v3")
    flags = _cpu.cpu_flags()
    if flags is not None:  # (Linux) import mipraster got here, so the check passed
        assert _cpu.missing_features(_build_info.X86_LEVEL, flags) == []


@pytest.mark.parametrize("drop, named", [("avx2", "avx2"), ("bmi2", "bmi2"), ("movbe", "movbe"), ("abm", "lzcnt")])
def test_a_v3_build_on_a_cpu_without_a_v3_feature_is_refused_by_name(tmp_path, drop, named):
    from mipraster import _cpu

    cpuinfo = tmp_path / "cpuinfo"
    cpuinfo.write_text("processor\t: 0\nflags\t\t: " + " ".join(f for f in V3_FLAGS.split() if f != drop) + "\n")
    with pytest.raises(ImportError, match=rf"x86-64-v3.*missing: {named}\).*MIPRASTER_X86_LEVEL=baseline"):
        _cpu.check_cpu("v3", str(cpuinfo))
    _cpu.check_cpu("baseline", str(cpuinfo))  # a baseline build runs anywhere


def test_a_v3_build_on_a_v3_cpu_loads():
    from mipraster import _cpu

    assert _cpu.missing_features("v3", V3_FLAGS.split()) == []
    assert _cpu.missing_features("v3", V3_FLAGS.replace("abm", "lzcnt").split()) == []
    assert _cpu.check_cpu("v3", "/nonexistent/cpuinfo") is None  # no flags to read: the modules decide
    with pytest.raises(ValueError, match="unknown x86-64 level 'v4'"):
        _cpu.missing_features("v4", [])
