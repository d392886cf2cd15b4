"""mypy's stubtest for pybind11 modules: ``python stubtest_pybind11.py [stubtest arguments]``.

stubtest reads a runtime signature with inspect.signature, which knows no pybind11 function (they
have no __text_signature__): on its own it checks names, properties and enum members but skips
every argument list. pybind11 writes the signatures into the first docstring line instead
(``name(a: T, b: T = 0, *, c: T = None) -> R``), and this wrapper gives stubtest those: names,
positional-only (``/`` and pybind11's unnamed ``arg0``...), keyword-only (``*``), ``*args``,
``**kwargs`` and defaults (literals and enum members as values, the others as unrepresentable).
Overloaded functions ("Overloaded function." docstrings) stay unchecked, and so does pybind11's
metaclass (the stubs do not name pybind11_type).
"""
import ast
import inspect
import re
import sys
from typing import Any, Iterator, List, Optional

from mypy import stubtest

_ENUM_REPR = re.compile(r"<(\w+)\.(\w+): -?\d+>$")
_UNNAMED = re.compile(r"arg\d+$")


def _split_top_level(text: str) -> List[str]:
    """``text`` split at the commas outside brackets and quotes."""
    parts, depth, quote, start = [], 0, "", 0
    for i, ch in enumerate(text):
        if quote:
            if ch == quote and text[i - 1] != "\\":
                quote = ""
        elif ch in "'\"":
            quote = ch
        elif ch in "([{<":
            depth += 1
        elif ch in ")]}>" and not (ch == ">" and text[i - 1] == "-"):
            depth -= 1
        elif ch == "," and depth == 0:
            parts.append(text[start:i].strip())
            start = i + 1
    if text[start:].strip():
        parts.append(text[start:].strip())
    return parts


def _default(text: str, runtime: Any) -> Any:
    try:
        return ast.literal_eval(text)
    except (ValueError, SyntaxError):
        pass
    match = _ENUM_REPR.match(text)
    module = sys.modules.get(getattr(runtime, "__module__", None) or "")
    if match and module is not None:
        enum = getattr(module, match.group(1), None)
        if enum is not None and hasattr(enum, match.group(2)):
            return getattr(enum, match.group(2))
    return stubtest.UNREPRESENTABLE


def pybind11_signature(runtime: Any) -> Optional[inspect.Signature]:
    """The signature in the first line of a pybind11 function's docstring, or None."""
    doc = getattr(runtime, "__doc__", None)
    name = getattr(runtime, "__name__", None)
    if not isinstance(doc, str) or not name or "\nOverloaded function." in doc:
        return None
    line = doc.lstrip().split("\n", 1)[0]
    if not line.startswith(name + "("):
        return None
    inner, depth = line[len(name) + 1:], 1
    for end, ch in enumerate(inner):  # the parenthesis that closes the argument list
        depth += {"(": 1, ")": -1}.get(ch, 0)
        if depth == 0:
            break
    else:
        return None
    parts = _split_top_level(inner[:end])
    unnamed = any(_UNNAMED.match(p.split(":")[0]) for p in parts)  # (then self is positional too)
    positional = "/" in parts
    keyword = False
    params = []
    for part in parts:
        if part in ("/", "*"):
            positional, keyword = False, part == "*"
            continue
        head, _, default = part.partition(" = ")
        arg = head.split(":", 1)[0].strip()
        if arg.startswith("**"):
            params.append(inspect.Parameter(arg[2:], inspect.Parameter.VAR_KEYWORD))
            continue
        if arg.startswith("*"):
            params.append(inspect.Parameter(arg[1:], inspect.Parameter.VAR_POSITIONAL))
            keyword = True
            continue
        if keyword:
            kind = inspect.Parameter.KEYWORD_ONLY
        elif positional or _UNNAMED.match(arg) or (unnamed and arg == "self"):
            kind = inspect.Parameter.POSITIONAL_ONLY
        else:
            kind = inspect.Parameter.POSITIONAL_OR_KEYWORD
        value = _default(default, runtime) if default else inspect.Parameter.empty
        params.append(inspect.Parameter(arg, kind, default=value))
    try:
        return inspect.Signature(params)
    except ValueError:  # (an order inspect refuses: leave the function unchecked)
        return None


def main() -> int:
    for attr in ("safe_inspect_signature", "_verify_metaclass", "UNREPRESENTABLE", "main"):
        assert hasattr(stubtest, attr), f"mypy.stubtest.{attr} is gone: update {__file__}"
    inspect_signature = stubtest.safe_inspect_signature
    verify_metaclass = stubtest._verify_metaclass

    def safe_inspect_signature(runtime: Any) -> Optional[inspect.Signature]:
        return inspect_signature(runtime) or pybind11_signature(runtime)

    def _verify_metaclass(stub: Any, runtime: Any, *args: Any, **kwargs: Any) -> Iterator[Any]:
        if type(runtime).__name__ != "pybind11_type":
            yield from verify_metaclass(stub, runtime, *args, **kwargs)

    stubtest.safe_inspect_signature = safe_inspect_signature
    stubtest._verify_metaclass = _verify_metaclass
    return stubtest.main()


if __name__ == "__main__":
    sys.exit(main())
