"""design-pid before and after issue 26's PID redesign (one pipeline over a
``Plant``), A/B in the same run: the library call on the seed's plant (fc
3500 Hz, zeta 0.2, LM741, ZN) and on a model plant (``K=2 tau=1m
theta=200u``, AMIGO), each with and without its SPICE run, timed in this tree
and in a copy of the commit before the redesign (:data:`BASE`, extracted with
``git archive`` into a temporary folder and imported from there in its own
process). The two trees' processes alternate, round by round, so that the
shared machine's load falls on both alike.

Goal: the redesign no slower, the ratio new/old of the medians at most
:data:`GOAL_RATIO` (1 plus the run-to-run noise measured here: the spread of
the old tree's own rounds).
"""

from __future__ import annotations

import json
import statistics
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
#: the commit before the redesign
BASE = "88d0b0b"
#: new/old median at most this (no slower, within the noise of a shared 2-core machine)
GOAL_RATIO = 1.10
ROUNDS, CALLS = 3, 3

WORKER = r"""
import json, sys, time
from designer.pid.design import design_pid
from designer.pid.spec import PidSpec
cases = {"seed plant, ZN": dict(plant_fc_hz=3500, plant_zeta=0.2, opamp="LM741"),
         "model plant, AMIGO": dict(plant_tf="K=2 tau=1m theta=200u", tuning="amigo", opamp="LM741")}
out = {}
for name, kw in cases.items():
    for sim in (False, True):
        design_pid(PidSpec(**kw), simulate=sim)          # warm: imports, caches, the simulator loaded
        times = []
        for _ in range(int(sys.argv[1])):
            tick = time.perf_counter()
            design_pid(PidSpec(**kw), simulate=sim)
            times.append(time.perf_counter() - tick)
        out[f"{name}{', SPICE' if sim else ', no SPICE'}"] = times
print(json.dumps(out))
"""


def _tree_of(commit: str, into: Path) -> Path:
    """``designer/`` of ``commit`` extracted under ``into`` (git archive, no worktree left behind)."""
    archive = into / "base.tar"
    with open(archive, "wb") as fh:
        subprocess.run(["git", "-C", str(ROOT), "archive", commit, "designer"], stdout=fh, check=True)
    with tarfile.open(archive) as tar:
        tar.extractall(into, filter="data")
    return into


def _run(path: Path, cwd: Path) -> dict:
    import os
    env = dict(os.environ, PYTHONPATH=str(path), MPLBACKEND="Agg")
    p = subprocess.run([sys.executable, "-c", WORKER, str(CALLS)], capture_output=True, text=True, env=env,
                       cwd=cwd, timeout=900)
    if p.returncode != 0:
        raise RuntimeError(p.stderr.strip().splitlines()[-1] if p.stderr.strip() else "worker failed")
    return json.loads(p.stdout.strip().splitlines()[-1])


def main():
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        (tmp / "old").mkdir()
        old_tree = _tree_of(BASE, tmp / "old")
        new, old = {}, {}
        for _ in range(ROUNDS):
            for store, tree in ((old, old_tree), (new, ROOT)):
                for k, v in _run(tree, tmp).items():
                    store.setdefault(k, []).extend(v)
    print(f"### design_pid in-process, this tree against {BASE} (before the redesign), "
          f"{ROUNDS} alternating rounds x {CALLS} calls, median (s)\n")
    print(f"Goal: new/old <= {GOAL_RATIO:g} (no slower, within a shared machine's noise).\n")
    print("| case | before (s) | after (s) | after/before | spread of before (max/min) | goal |")
    print("|---|---:|---:|---:|---:|---|")
    for k in old:
        a, b = statistics.median(old[k]), statistics.median(new[k])
        ratio = b / a
        print(f"| {k} | {a:.3f} | {b:.3f} | {ratio:.2f} | {max(old[k]) / min(old[k]):.2f} | "
              f"{'ok' if ratio <= GOAL_RATIO else 'MISSED'} |")


if __name__ == "__main__":
    main()
