"""check-design on the dogfood specs (specs/*.yaml): its overhead beyond the
simulations it runs.

"Bare simulation time" of a spec corner: the simulator backend's run of that
corner's deck alone (the design's deck, or the user's), with the vectors
check-design reads, in one warm process, median of 3. Goal (issue
10): ``check-design specs/*.yaml --jobs 2`` end to end, in a new process
(imports, YAML, workers, JUnit and summary files), takes no more than 1.2 x the
sum of the bare times divided by 2, i.e. an overhead per spec under 0.3 s beyond
the simulations. Both backends.

The floor of that goal is measured too, in the same run: the same decks and
nothing else, run by the same two worker processes (``designer.core.workers``,
longest first, each worker's ngspice warmed). On two cores no checker can beat
it: what check-design adds beyond it is its own overhead (interpreter, imports,
YAML, the analysis of each corner, the files). Where the floor alone is
already near 1.2 x sum / 2 (the decks cannot be split evenly in two, and two
ngspice runs side by side each run slower than one alone), the ratio goal
leaves no room for a Python process at all, and the floor says so.
"""

from __future__ import annotations

import os
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
    """(spec, corner) -> ([deck texts], folder to run them in): every simulation check-design runs for
    the corner (a plant's step deck and its sine check's ``.ac`` deck; a loop's deck; the user's deck)."""
    from designer.plant.netlist import plant_ac_deck
    out = {}
    for s in specs:
        for k, corner in enumerate(s.corners):
            if s.kind == "netlist":
                out[(s.name, corner)] = ([s.designs[k]], None)
                continue
            if s.kind == "filter":    # its cascade's .ac over the check's own sweep
                from designer.check.filter_kind import corner_stages, model_grid, spice_sweep
                from designer.core import opamps
                from designer.filters.cascade import Cascade
                from designer.filters.deck import ac_deck
                from designer.filters.registry import get
                case = s.designs[k]
                _, stages, _ = corner_stages(case)
                netlist, f_lo, f_hi, ppd = spice_sweep(Cascade([(get(t), v) for t, v in stages]),
                                                       model_grid(stages, case.mask), case.mask)
                out[(s.name, corner)] = ([ac_deck(netlist, opamps.get(case.opamp), f_lo, f_hi,
                                                  points_per_decade=ppd)], None)
                continue
            if s.kind == "plant":
                from designer.plant.design import analyze_plant as analyze, design_plant as design
            else:
                from designer.pid.design import analyze_pid as analyze, design_pid as design
            res = (analyze if s.analyze else design)(s.designs[k], simulate=False)
            runs = [res.deck]
            if s.kind == "plant":
                fn = res.built.fn_hz
                runs.append(plant_ac_deck(res.built, res.opamp, fn / 100, fn * 100, "sine check"))
            out[(s.name, corner)] = (runs, None)
    return out


def _simulate_all(sim, runs, cwd) -> None:
    for deck in runs:
        sim.run(deck)


def bare_times(runs: dict, simulator: str) -> dict:
    """(spec, corner) -> median seconds of the corner's simulations alone (the backend's runs of its
    decks, with the vectors check-design reads), in a warm process."""
    from designer.spice.simulate import get_simulator
    sim = get_simulator(simulator)
    out = {}
    for key, (corner_decks, cwd) in runs.items():
        _simulate_all(sim, corner_decks, cwd)   # warm: the shared library, caches
        times = []
        for _ in range(3):
            tick = time.perf_counter()
            _simulate_all(sim, corner_decks, cwd)
            times.append(time.perf_counter() - tick)
        out[key] = statistics.median(times)
    return out


def pool_floor(runs: dict, bare: dict, simulator: str, repeat: int = 3) -> float:
    """Median wall seconds of the corners' decks alone, run by ``JOBS`` warm worker processes
    (the pool check-design uses, longest first): the least any checker can take here."""
    from designer.core.workers import run_tasks
    from designer.spice.simulate import get_simulator
    keys = list(runs)
    sim = get_simulator(simulator)
    light = runs[min(keys, key=lambda k: bare[k])]

    def setup():
        # each worker's simulator loaded (the shared library's start), with the lightest deck
        _simulate_all(sim, light[0], light[1])

    def work(key):
        corner_decks, cwd = runs[key]
        _simulate_all(sim, corner_decks, cwd)

    walls = []
    for _ in range(repeat):
        tick = time.perf_counter()
        run_tasks(keys, work, JOBS, 600, lambda task, why: None, setup, lambda key: bare[key])
        walls.append(time.perf_counter() - tick)
    return statistics.median(walls)


def main():
    from designer.check.spec import load_spec
    paths = sorted((ROOT / "specs").glob("*.yaml"))
    specs = [load_spec(p, root=ROOT) for p in paths]   # one reads a reference result in reports/
    print(f"### check-design on {len(specs)} dogfood specs "
          f"({sum(len(s.corners) for s in specs)} corners), --jobs {JOBS}\n")
    print("| simulator | sum of bare times (s) | goal: 1.2 x sum / 2 (s) | floor: the decks alone in 2 workers (s) "
          "| check-design wall (s) | | overhead per spec: (wall - sum / 2) / specs (s) | goal < 0.3 s "
          "| beyond the floor, per spec (s) |")
    print("|---|---|---|---|---|---|---|---|---|")
    details = []
    runs = decks(specs)
    for simulator in ("pyspice", "ngspice-cli"):
        bare = bare_times(runs, simulator)
        floor = pool_floor(runs, bare, simulator)
        total = sum(bare.values())
        goal = RATIO_GOAL * total / JOBS
        walls = []
        with tempfile.TemporaryDirectory() as tmp:
            for _ in range(3):
                wall, _mb, code = run_measured([str(ROOT / ".venv" / "bin" / "check-design"), *map(str, paths),
                                                "--root", str(ROOT), "--jobs", str(JOBS), "--simulator", simulator,
                                                "--junit", f"{tmp}/j.xml", "--summary", f"{tmp}/s.md"])
                assert code == 1, f"check-design exit status {code} (the seed's spec must fail: 1)"
                walls.append(wall)
        wall = statistics.median(walls)
        per_spec = (wall - total / JOBS) / len(specs)
        verdict = lambda ok: "ok" if ok else "MISSED"  # noqa: E731
        beyond = (wall - floor) / len(specs)
        print(f"| {simulator} | {total:.2f} | {goal:.2f} | {floor:.2f} | {wall:.2f} | {verdict(wall <= goal)} "
              f"| {per_spec:+.2f} | {verdict(per_spec < PER_SPEC_GOAL_S)} | {beyond:+.2f} |")
        details.append((simulator, bare))
    for simulator, bare in details:
        print(f"\nBare times, {simulator}: " + ", ".join(f"{n}[{c or '-'}] {t:.2f} s" for (n, c), t in bare.items()))
    print(f"\nLoad average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores when it ended (a shared machine: "
          "the per-spec overhead is seconds, and grows with the load as the simulations do).")


if __name__ == "__main__":
    main()
