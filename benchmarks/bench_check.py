"""check-design on the dogfood specs (specs/*.yaml): its overhead beyond the
simulations it runs.

"Bare simulation time" of a spec corner: the simulator backend's run of that
corner's deck alone (the design's deck, or the user's), with the vectors
check-design reads, in one warm process, median of 3. Goal (issue
10): ``check-design specs/*.yaml --jobs 2`` end to end, in a new process
(imports, YAML, workers, JUnit and summary files), takes no more than 1.2 x the
sum of the bare times divided by 2, i.e. an overhead per spec under 0.3 s beyond
the simulations. Both backends.
"""

from __future__ import annotations

import statistics
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
from bench_plant import run_measured  # noqa: E402  (one home for the new-process measure)

JOBS = 2
RATIO_GOAL, PER_SPEC_GOAL_S = 1.2, 0.3


def decks(specs) -> dict:
    """(spec, corner) -> (deck text, folder to run it in): what check-design simulates for each corner."""
    out = {}
    for s in specs:
        for k, corner in enumerate(s.corners):
            if s.kind == "netlist":
                out[(s.name, corner)] = (s.designs[k], s.deck_dir)
                continue
            if s.kind == "plant":
                from designer.plant.design import analyze_plant as analyze, design_plant as design
            else:
                from designer.pid.design import analyze_pid as analyze, design_pid as design
            out[(s.name, corner)] = ((analyze if s.analyze else design)(s.designs[k], simulate=False).deck, None)
    return out


def bare_times(runs: dict, simulator: str) -> dict:
    """(spec, corner) -> median seconds of the corner's simulation alone (the backend's run of its
    deck, with the vectors check-design reads), in a warm process."""
    from designer.spice.simulate import get_simulator
    sim = get_simulator(simulator)
    out = {}
    for key, (deck, cwd) in runs.items():
        sim.run(deck, workdir=cwd)   # warm: the shared library, caches
        times = []
        for _ in range(3):
            tick = time.perf_counter()
            sim.run(deck, workdir=cwd)
            times.append(time.perf_counter() - tick)
        out[key] = statistics.median(times)
    return out


def main():
    from designer.check.spec import load_spec
    paths = sorted((ROOT / "specs").glob("*.yaml"))
    specs = [load_spec(p) for p in paths]
    print(f"### check-design on {len(specs)} dogfood specs "
          f"({sum(len(s.corners) for s in specs)} corners), --jobs {JOBS}\n")
    print("| simulator | sum of bare times (s) | goal: 1.2 x sum / 2 (s) | check-design wall (s) | | "
          "overhead per spec: (wall - sum / 2) / specs (s) | goal < 0.3 s |")
    print("|---|---|---|---|---|---|---|")
    details = []
    runs = decks(specs)
    for simulator in ("pyspice", "ngspice-cli"):
        bare = bare_times(runs, simulator)
        total = sum(bare.values())
        goal = RATIO_GOAL * total / JOBS
        walls = []
        with tempfile.TemporaryDirectory() as tmp:
            for _ in range(3):
                wall, _mb, code = run_measured([str(ROOT / ".venv" / "bin" / "check-design"), *map(str, paths),
                                                "--jobs", str(JOBS), "--simulator", simulator,
                                                "--junit", f"{tmp}/j.xml", "--summary", f"{tmp}/s.md"])
                assert code == 1, f"check-design exit status {code} (the seed's spec must fail: 1)"
                walls.append(wall)
        wall = statistics.median(walls)
        per_spec = (wall - total / JOBS) / len(specs)
        verdict = lambda ok: "ok" if ok else "MISSED"  # noqa: E731
        print(f"| {simulator} | {total:.2f} | {goal:.2f} | {wall:.2f} | {verdict(wall <= goal)} | {per_spec:+.2f} "
              f"| {verdict(per_spec < PER_SPEC_GOAL_S)} |")
        details.append((simulator, bare))
    for simulator, bare in details:
        print(f"\nBare times, {simulator}: " + ", ".join(f"{n}[{c or '-'}] {t:.2f} s" for (n, c), t in bare.items()))


if __name__ == "__main__":
    main()
