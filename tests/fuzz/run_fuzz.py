"""Runs one fuzz target under atheris (pip install atheris).

    python tests/fuzz/run_fuzz.py TARGET [libFuzzer options]
    python tests/fuzz/run_fuzz.py scene -runs=1000000 tests/fuzz/corpus/scene
    python tests/fuzz/run_fuzz.py render -max_total_time=60 tests/fuzz/corpus/render

TARGET is scene, image or render (see fuzz_targets.py). A corpus folder given after the options
is read first and, by libFuzzer's rule, new interesting inputs are written into it: point it at a
scratch copy to keep the committed corpus small. Exit status 0 when no input failed.
"""
import os
import sys

import atheris

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

with atheris.instrument_imports(include=["mipraster", "fuzz_targets"]):
    import fuzz_targets


def main() -> None:
    if len(sys.argv) < 2 or sys.argv[1] not in fuzz_targets.TARGETS:
        sys.exit(f"usage: run_fuzz.py {{{','.join(fuzz_targets.TARGETS)}}} [libFuzzer options] [corpus dirs]")
    target = fuzz_targets.TARGETS[sys.argv[1]]
    atheris.Setup([sys.argv[0]] + sys.argv[2:], lambda data: target(bytes(data)))
    atheris.Fuzz()


if __name__ == "__main__":
    main()
