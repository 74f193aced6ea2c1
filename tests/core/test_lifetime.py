"""designer.core.lifetime: stop signals give 128 + the signal and one line, also
while ngspice's shared library runs; children die with their parent."""

import os
import signal
import subprocess
import sys
import textwrap
import time
import uuid

import pytest

from designer.core import lifetime
from helpers import tagged_env, wait_gone


def test_statuses_are_what_a_shell_reports():
    assert lifetime.Interrupted(signal.SIGTERM).status == 143
    assert lifetime.Interrupted(signal.SIGHUP).status == 129
    assert lifetime.status_of(KeyboardInterrupt()) == 130
    assert lifetime.words_of(lifetime.Interrupted(signal.SIGHUP)) == "hung up (SIGHUP)"
    assert isinstance(lifetime.Interrupted(), KeyboardInterrupt)   # every `finally` on the way runs


def _python(code: str, tag: str, **kw):
    return subprocess.Popen([sys.executable, "-c", textwrap.dedent(code)], env=tagged_env(tag),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kw)


@pytest.mark.spice
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP])
def test_a_signal_inside_the_shared_library_ends_the_run_at_once(sig):
    # a transient of seconds that prints as it runs (PySpice's callbacks: Python inside the C call);
    # KeyboardInterrupt raised there is swallowed by cffi, and the run would go on to the end
    tag = uuid.uuid4().hex
    p = _python("""
        import sys
        from designer.core import lifetime
        from designer.spice.simulate import PySpiceShared
        lifetime.install("probe")
        deck = ("long\\nV1 in 0 SIN(0 1 1k)\\nR1 in out 1k\\nC1 out 0 100n\\n.tran 100n 2\\n"
                ".meas tran vmax MAX v(out)\\n.end\\n")
        PySpiceShared().run("t\\nV1 in 0 1\\nR1 in 0 1k\\n.tran 1u 10u\\n.end\\n")   # loaded and warm
        print("running", flush=True)
        PySpiceShared().run(deck)
        print("finished", flush=True)
    """, tag)
    assert p.stdout.readline().strip() == "running"
    time.sleep(0.5)
    tick = time.monotonic()
    p.send_signal(sig)
    out, err = p.communicate(timeout=120)
    assert time.monotonic() - tick < 5, "the simulation ran on"
    assert p.returncode == 128 + sig and "finished" not in out
    assert err.splitlines() == [f"probe: error: {lifetime.WORDS[sig]}"], err


def test_a_child_dies_with_its_parent_however_the_parent_dies():
    tag = uuid.uuid4().hex
    # the parent forks a child that asks to die with it, then sleeps; the parent is SIGKILLed
    p = _python("""
        import os, time
        from designer.core import lifetime
        parent = os.getpid()
        if os.fork() == 0:
            lifetime.die_with_parent(parent)
            time.sleep(60)
            os._exit(0)
        print("forked", flush=True)
        time.sleep(60)
    """, tag)
    assert p.stdout.readline().strip() == "forked"
    time.sleep(0.2)
    p.kill()
    p.communicate(timeout=10)
    assert wait_gone(tag) == []


def test_an_ngspice_subprocess_dies_with_its_parent():
    tag = uuid.uuid4().hex
    p = _python("""
        import subprocess, sys
        from designer.core import lifetime
        child = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"], preexec_fn=lifetime.preexec())
        print("started", flush=True)
        child.wait()
    """, tag)
    assert p.stdout.readline().strip() == "started"
    p.kill()
    p.communicate(timeout=10)
    assert wait_gone(tag) == []


def test_a_worker_pipe_is_not_held_open_by_the_worker_itself():
    # the renderer used to hold both ends of its pipe: its parent's death went unseen
    import multiprocessing

    from designer.core.workers import Worker
    w = Worker(multiprocessing.get_context("fork"), lambda task: task)
    try:
        w.give(0, "ping", 10)
        assert w.conn.recv() == ("ok", "ping")
        fds = {os.readlink(f"/proc/{w.proc.pid}/fd/{fd}") for fd in os.listdir(f"/proc/{w.proc.pid}/fd")}
        mine = os.readlink(f"/proc/self/fd/{w.conn.fileno()}")
        assert mine not in fds
    finally:
        w.kill()


def test_a_signal_lost_in_a_callback_python_cannot_raise_from_is_delivered_again():
    # the kill tests once caught SIGINT landing in the import machinery's weakref callback: Python
    # printed "Exception ignored" with a traceback and went on; here a weakref callback is the place
    tag = uuid.uuid4().hex
    p = _python("""
        import gc, os, signal, sys, time, weakref
        from designer.core import lifetime
        lifetime.install("probe")
        class Thing:
            pass
        t = Thing()
        weakref.ref(t, lambda ref: os.kill(os.getpid(), signal.SIGTERM) or time.sleep(0.01) or sum(range(10)))
        keep = weakref.ref(t, lambda ref: (os.kill(os.getpid(), signal.SIGTERM), [i for i in range(1000)]))
        try:
            del t
            gc.collect()
            for _ in range(100):
                time.sleep(0.01)
            print("went on", flush=True)
        except KeyboardInterrupt as exc:
            print(f"probe: error: {lifetime.words_of(exc)}", file=sys.stderr)
            sys.exit(lifetime.status_of(exc))
    """, tag)
    out, err = p.communicate(timeout=60)
    assert "went on" not in out and "Exception ignored" not in err and "Traceback" not in err, err
    assert p.returncode == 143 and err.splitlines() == ["probe: error: terminated (SIGTERM)"], err


def test_finish_exits_with_the_status_after_what_a_normal_exit_does(tmp_path):
    """finish(): the status, buffered output flushed, a thread that is not a daemon joined,
    the atexit handlers run (multiprocessing's among them), and a closed pipe stays silent."""
    script = textwrap.dedent(f"""
        import atexit, sys, threading, time
        from designer.core import lifetime
        def late():
            time.sleep(0.3)
            open({str(tmp_path / "thread")!r}, "w").write("joined")
        threading.Thread(target=late).start()
        atexit.register(lambda: open({str(tmp_path / "atexit")!r}, "w").write("ran"))
        sys.stdout.write("x" * 100000)       # more than a pipe holds: flushed by finish
        lifetime.finish(3)
        print("never")
    """)
    p = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60)
    assert p.returncode == 3 and p.stderr == ""
    assert p.stdout == "x" * 100000
    assert (tmp_path / "thread").read_text() == "joined" and (tmp_path / "atexit").read_text() == "ran"
    # a reader that stopped early (| head): no "Exception ignored" line, the status kept
    proc = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    proc.stdout.read(10)
    proc.stdout.close()
    with proc.stderr:
        err = proc.stderr.read().decode()
    assert proc.wait(60) == 3 and "Exception" not in err and "Error" not in err


def test_a_console_command_ends_through_finish():
    """The console scripts exit through finish (the status, the output whole)."""
    exe = os.path.join(os.path.dirname(sys.executable), "design-plant")
    p = subprocess.run([exe, "--fc", "3500", "--zeta", "0.2", "--no-sim", "--no-files", "--json"],
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 0 and p.stderr == "" and p.stdout.rstrip().endswith("}")
    bad = subprocess.run([exe, "--fc", "-1", "--zeta", "0.2"], capture_output=True, text=True, timeout=120)
    assert bad.returncode == 2 and bad.stdout == "" and len(bad.stderr.strip().splitlines()) == 1


def test_stale_folders_are_those_of_gone_owners_only(tmp_path):
    """Issue 25: what a SIGKILLed server or command left was never removed."""
    gone = subprocess.Popen(["true"])
    gone.wait()
    stale = [f"designer-web-{gone.pid}-a", f"designer-sim-{gone.pid}-b", f"designer-init-{gone.pid}-c"]
    alive = [f"designer-web-{os.getppid()}-d", f"designer-sim-{os.getpid()}-e", "designer-sim-f00", "other-1-x"]
    for name in stale + alive:
        (tmp_path / name / "sub").mkdir(parents=True)
    (tmp_path / f"designer-web-{gone.pid}-file").write_text("a file, not a folder")
    (tmp_path / f"designer-web-{gone.pid}-link").symlink_to(tmp_path / alive[0])
    alive += [f"designer-web-{gone.pid}-file", f"designer-web-{gone.pid}-link"]
    if os.getuid() == 0:
        (tmp_path / f"designer-web-{gone.pid}-theirs").mkdir()
        os.chown(tmp_path / f"designer-web-{gone.pid}-theirs", 65534, 65534)
        alive.append(f"designer-web-{gone.pid}-theirs")
    assert sorted(lifetime.remove_stale(str(tmp_path))) == sorted(stale)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(alive)
    assert lifetime.owned_prefix("sim") == f"designer-sim-{os.getpid()}-"
    assert lifetime.remove_stale(str(tmp_path / "nowhere")) == []


def test_what_a_handler_leaves_for_the_end_of_a_native_block_runs_there_once():
    """Issue 29: a signal handled inside ngspice's callbacks (where cffi swallows what is raised) leaves its
    exception for the end of the native block: raised there, before the block's caller goes on, once."""
    ran = []

    def stop():
        ran.append(lifetime.in_native())
        raise lifetime.Interrupted()

    lifetime.after_native(stop)   # outside a block: waits for the next one's end
    with pytest.raises(lifetime.Interrupted):
        with lifetime.native():
            with lifetime.native():   # an inner block's end is not the end
                lifetime.after_native(stop)
            assert ran == []
    assert ran == [False]
    with lifetime.native():        # done with: not again
        pass
    assert ran == [False]
