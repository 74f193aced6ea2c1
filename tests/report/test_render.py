"""designer.report.render: pictures drawn in the renderer process are the ones
drawn in-process, byte for byte; a renderer that fails, dies or is never
started leaves the drawing to the caller, and a real error surfaces there with
its own type. The console scripts (which start the renderer) write the same
bundle as the commands called in-process (which do not)."""

import filecmp
import os
import subprocess
from pathlib import Path

import pytest

from designer.cli.launch import draws
from designer.cli.plant import design_plant_main
from designer.plant.design import design_plant
from designer.plant.report import bode_png, schematic, step_png
from designer.plant.spec import PlantSpec
from designer.report import render
from designer.report.bundle import schematic_pictures
from helpers import script


@pytest.fixture(scope="module")
def plant():
    return design_plant(PlantSpec(fc_hz=3500, zeta=0.2), simulate=False)


@pytest.fixture
def renderer():
    render.start(preload=("designer.plant.report",))
    assert render.running()
    yield
    render.stop()


def square(x):
    return x * x


def fails(x):
    raise ValueError(f"bad {x}")


def dies_in_renderer(x):
    # the renderer's process ends mid-task; in the caller this returns
    if render._in_renderer:
        os._exit(7)
    return x + 1


def test_pictures_from_the_renderer_are_those_drawn_here(plant, renderer):
    here = [schematic_pictures(schematic, plant), step_png(plant), bode_png(plant)]
    there = render.submit_many([(schematic_pictures, (schematic, plant)), (step_png, (plant,)),
                                (bode_png, (plant,))]).result()
    assert there == here
    assert there[1][:8] == b"\x89PNG\r\n\x1a\n" and "<svg" in there[0][0]


def test_tasks_answer_in_order_whatever_is_asked_first(renderer):
    pending = [render.submit(square, k) for k in range(5)]
    assert [p.result() for p in reversed(pending)] == [16, 9, 4, 1, 0]


def test_an_error_in_the_renderer_is_raised_in_the_caller_with_its_type(renderer):
    with pytest.raises(ValueError, match="bad 3"):
        render.submit(fails, 3).result()
    assert render.submit(square, 4).result() == 16   # the renderer lives on


def test_a_renderer_that_dies_leaves_the_drawing_to_the_caller(renderer):
    assert render.submit(dies_in_renderer, 1).result() == 2
    assert not render.running()
    assert render.submit(square, 3).result() == 9   # no renderer: in-process


def test_a_helper_that_dies_is_redrawn_by_the_renderer(renderer):
    out = render.submit_many([(square, (2,)), (helper_dies_here, (5,)), (square, (3,))]).result()
    assert out == [4, -5, 9]
    assert render.running()


def helper_dies_here(x):
    # in a helper, the parent is the renderer; in the renderer, the parent is this test's process
    if render._in_renderer and os.getppid() != _TEST_PID:
        os._exit(3)
    return -x


_TEST_PID = os.getpid()


def test_a_failing_first_call_still_reaps_its_helpers_and_raises_here(renderer):
    big = 1 << 20   # a helper's answer larger than a pipe's buffer: it waits until read
    with pytest.raises(ValueError, match="bad 1"):
        render.submit_many([(fails, (1,)), (bytes, (big,)), (square, (2,))]).result()
    assert render.running()
    assert render.submit_many([(square, (2,)), (bytes, (big,))]).result() == [4, bytes(big)]


def test_without_a_renderer_everything_is_drawn_here():
    assert not render.running()
    assert render.submit_many([(square, (2,)), (square, (3,))]).result() == [4, 9]
    with pytest.raises(ValueError):
        render.submit(fails, 1).result()


def test_stop_ends_the_renderer_at_once_even_while_it_imports():
    render.start(preload=("designer.plant.report",))
    proc = render._worker.proc
    render.stop()
    assert not proc.is_alive() and not render.running()


@pytest.mark.parametrize("argv, drawn", [
    (["--fc", "3500", "--zeta", "0.2"], True),
    (["--fc", "3500", "--zeta", "0.2", "--no-files"], False),
    (["--fc", "3500", "--no-fi", "--zeta", "0.2"], False),   # argparse takes the abbreviation
    (["--no-sim"], True),
    (["--help"], False),
    (["-h"], False),
    (["--version"], False),
])
def test_which_command_lines_draw(argv, drawn):
    assert draws(argv) is drawn


@pytest.mark.spice
def test_the_console_script_writes_what_the_command_writes_in_process(tmp_path):
    match = same_bundles(tmp_path, "design-plant", design_plant_main, ["--fc", "3500", "--zeta", "0.2", "--name", "p"])
    assert {"step.png", "bode.png", "schematic.png", "build-sheet.html"} <= match


def same_bundles(tmp_path, command: str, main, args) -> set:
    """The files of the console script's bundle (renderer started) that equal the in-process
    command's, byte for byte; asserts that every file but result.json (which records the argv) does."""
    run = subprocess.run([script(command), *args, "--out", str(tmp_path / "a")], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert main([*args, "--out", str(tmp_path / "b")]) == 0
    name = args[args.index("--name") + 1]
    a, b = tmp_path / "a" / "reports" / name, tmp_path / "b" / "reports" / name
    names = sorted(p.name for p in a.iterdir())
    assert names == sorted(p.name for p in b.iterdir())
    same = [n for n in names if n != "result.json"]
    match, mismatch, errors = filecmp.cmpfiles(a, b, same, shallow=False)
    assert not mismatch and not errors, mismatch
    return set(match)


@pytest.mark.spice
def test_the_renderer_never_writes_to_the_terminal(tmp_path):
    # matplotlib warns on stderr when its config folder is unusable (as when it builds its font
    # cache); the renderer, started before the arguments are read, must not add that to the output
    env = {**os.environ, "MPLCONFIGDIR": os.path.join(os.devnull, "mpl")}
    ok = subprocess.run([script("design-plant"), "--fc", "3500", "--zeta", "0.2", "--out", str(tmp_path / "o")],
                        capture_output=True, text=True, env=env)
    assert ok.returncode == 0 and ok.stderr == "", ok.stderr
    bad = subprocess.run([script("design-plant"), "--fc", "3500", "--zeta", "9e9"], capture_output=True, text=True,
                         env=env)
    assert bad.returncode == 2 and len(bad.stderr.splitlines()) == 1, bad.stderr


@pytest.mark.spice
def test_an_interrupt_ends_the_renderer_too(tmp_path):
    import signal
    import time
    out = tmp_path / "interrupted"
    p = subprocess.Popen([script("design-pid"), "--plant-fc", "3500", "--plant-zeta", "0.2", "--tuning", "optimize",
                          "--target-overshoot", "10", "--out", str(out)], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True,
                         preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    time.sleep(0.6)   # the renderer is started and the tuning runs (the whole run takes over a second)
    p.send_signal(signal.SIGINT)
    _, err = p.communicate(timeout=60)
    assert p.returncode == 130 and err.splitlines() == ["design-pid: error: interrupted"], err
    # the renderer and its helpers are forks of the command: the same command line
    deadline = time.monotonic() + 5
    while running_with(str(out)) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not running_with(str(out))
    assert not (out / "reports").exists() or not any((out / "reports").iterdir())


def running_with(arg: str) -> list:
    """Processes whose command line has ``arg`` (read from /proc: no ps needed)."""
    found = []
    for d in Path("/proc").iterdir():
        try:
            if d.name.isdigit() and arg.encode() in (d / "cmdline").read_bytes():
                found.append(int(d.name))
        except OSError:   # gone meanwhile
            pass
    return found


@pytest.mark.spice
def test_pictures_drawn_during_the_spice_run_are_those_drawn_after_it(tmp_path):
    # design-pid for a model plant sends the schematic, loop-bode.png and reaction-curve.png to the
    # renderer before its SPICE run (they read none of it): the console script's bundle, drawn so, is
    # the bundle of the command called in-process, which draws everything after the run
    from designer.cli.pid import design_pid_main
    args = ["--plant-tf", "K=2 tau=1m theta=200u", "--tuning", "simc", "--simulator", "ngspice-cli", "--name", "m"]
    assert {"schematic.png", "loop-bode.png", "reaction-curve.png", "closed-loop.png",
            "build-sheet.html"} <= same_bundles(tmp_path, "design-pid", design_pid_main, args)
