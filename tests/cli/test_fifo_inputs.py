"""A FIFO given as an input file, to the installed console scripts: refused in
one line from its stat, before it is opened (opening a FIFO that has no writer
blocks forever), with exit status 2, within a few seconds; the same through a
symbolic link, and a socket likewise."""

import os
import socket
import subprocess
import time

import pytest
from helpers import ROOT, script

STEP = ROOT / "tests" / "cli" / "corpus" / "files" / "step.csv"
#: command, its arguments with {fifo} for the FIFO, what the file is called in the message
CASES = [
    ("identify", ["{fifo}"], "capture file"),
    ("identify", [STEP, "--against", "{fifo}"], "--against file"),
    ("identify-freq", ["{fifo}"], "table"),
    ("identify-freq", ["{fifo}", "--json"], "table"),
    ("check-design", ["{fifo}"], "spec file"),
    ("analyze-pid", ["--plant-fc", "3500", "--plant-zeta", "0.2", "--parts-json", "{fifo}", "--no-sim"],
     "--parts-json file"),
    ("design-pid", ["--plant-json", "{fifo}", "--no-sim"], "--plant-json file"),
]


def _refused(cmd, args, path, tmp_path):
    argv = [script(cmd), *(str(a).replace("{fifo}", str(path)) for a in args)]
    tick = time.monotonic()
    proc = subprocess.run(argv, capture_output=True, text=True, timeout=60, cwd=tmp_path)
    seconds = time.monotonic() - tick
    assert proc.returncode == 2, (argv, proc.returncode, proc.stderr)
    assert proc.stdout == ""
    lines = proc.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"{cmd}: error: "), proc.stderr
    assert seconds < 20, f"{cmd} took {seconds:.1f} s"
    return lines[0]


@pytest.mark.parametrize("cmd, args, what", CASES, ids=[f"{c} {' '.join(map(str, a))}" for c, a, _ in CASES])
def test_a_fifo_is_refused_before_it_is_opened(tmp_path, cmd, args, what):
    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)
    line = _refused(cmd, args, fifo, tmp_path)
    assert f"{what} {fifo} is a FIFO (named pipe); a regular file is needed" in line, line
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pipe.csv"]   # nothing written


def test_a_link_to_a_fifo_and_a_socket_are_refused_too(tmp_path):
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    link = tmp_path / "capture.csv"
    link.symlink_to(fifo)
    assert "capture file " + str(link) + " is a FIFO (named pipe)" in _refused("identify", [link], link, tmp_path)
    sock_path = tmp_path / "s.csv"
    with socket.socket(socket.AF_UNIX) as sock:
        sock.bind(str(sock_path))
        assert "is a socket; a regular file is needed" in _refused("identify-freq", [sock_path], sock_path,
                                                                   tmp_path)
