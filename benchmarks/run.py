"""Run every ``benchmarks/bench_*.py`` (each has a ``main()`` that prints
Markdown) and write the collected output to ``benchmarks/RESULTS.md``.

Goals are checked and reported here, never in unit tests: the machines are
shared and noisy. ``python benchmarks/run.py [name ...]`` runs a subset.
"""

from __future__ import annotations

import contextlib
import importlib.util
import io
import os
import platform
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    benches = sorted(HERE.glob("bench_*.py"))
    if argv:
        benches = [b for b in benches if any(a in b.stem for a in argv)]
    parts = ["# Benchmark results\n",
             f"Run {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())} on {platform.machine()}, "
             f"{os.cpu_count()} cores, Python {platform.python_version()}, by `make bench`.\n"]
    failed = 0
    for path in benches:
        spec = importlib.util.spec_from_file_location(path.stem, path)
        mod = importlib.util.module_from_spec(spec)
        buf = io.StringIO()
        print(f"== {path.name}", file=sys.stderr)
        try:
            with contextlib.redirect_stdout(buf):
                spec.loader.exec_module(mod)
                mod.main()
        except Exception as exc:  # one broken benchmark must not hide the others
            failed += 1
            buf.write(f"\n**{path.name} failed: {type(exc).__name__}: {exc}**\n")
        text = buf.getvalue().strip()
        print(text, file=sys.stderr)
        parts.append(f"## {path.stem}\n\n{text}\n")
    (HERE / "RESULTS.md").write_text("\n".join(parts))
    print(f"wrote {HERE / 'RESULTS.md'}", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
