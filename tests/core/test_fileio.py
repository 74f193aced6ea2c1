"""Files and bundles are never half-written nor mixed: real processes killed at
every step of a bundle write, a real file-size limit standing in for a full disk."""

import json
import os
import resource
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from helpers import script

from designer.core.errors import DesignError
from designer.core.fileio import atomic_write, clean_stale, publish_folder

# A bundle writer run in a child process, which dies abruptly (os._exit, no cleanup)
# at a chosen step: the k-th file written in the staging folder, the link, the swap.
WRITER = textwrap.dedent("""
    import os, sys
    from pathlib import Path
    from designer.core import fileio
    from designer.report import bundle as B, document as R
    out, tag, step = sys.argv[1], sys.argv[2], sys.argv[3]
    counter = {"n": 0}
    real_write = Path.write_bytes
    def write_bytes(self, data):
        counter["n"] += 1
        if step == f"write{counter['n']}":
            os._exit(9)
        return real_write(self, data)
    Path.write_bytes = write_bytes
    def die_at(name, fn):
        def wrapped(*a, **k):
            if step == name:
                os._exit(9)
            return fn(*a, **k)
        return wrapped
    fileio.link_into = die_at("link", fileio.link_into)
    fileio.publish_folder = die_at("publish", fileio.publish_folder)
    if step == "between-renames":   # the two-rename fallback, killed in the middle
        fileio._exchange = lambda a, b: False
        real_rename = os.rename
        def rename(a, b):
            real_rename(a, b)
            if ".old-" in str(b):
                os._exit(9)
        os.rename = rename
    if step == "after-exchange":
        real_rmtree = fileio.remove_tree
        fileio.remove_tree = lambda p: os._exit(9)
    files = B.bundle_paths(out, "b", ["p.png"], {"extra": "extra.txt"})
    B.write_bundle(files, f"* deck {tag}\\n", {"p.png": tag.encode()}, f"title {tag}",
                   [("s", [R.text(tag)])], {"tag": tag}, {"extra": f"extra {tag}"})
""")

STEPS = ["write1", "write3", "write6", "link", "publish", "between-renames", "after-exchange"]


def write(out, tag, step="none"):
    return subprocess.run([sys.executable, "-c", WRITER, str(out), tag, step], capture_output=True, text=True,
                          timeout=60)


def bundle_tags(out: Path) -> set:
    """The run tag each file of the bundle comes from (the netlist read through its link)."""
    rep = out / "reports" / "b"
    return {(out / "netlists" / "b.cir").read_text().split()[-1],
            json.loads((rep / "result.json").read_text())["tag"],
            (rep / "p.png").read_text(), (rep / "extra.txt").read_text().split()[-1],
            (rep / "build-sheet.md").read_text().split()[-1]}


def temporaries(out: Path) -> list:
    return [p for p in out.rglob(".*")]


@pytest.mark.parametrize("step", STEPS)
def test_a_killed_write_leaves_the_old_bundle_or_the_new_one(tmp_path, step):
    assert write(tmp_path, "old").returncode == 0
    assert bundle_tags(tmp_path) == {"old"}
    died = write(tmp_path, "new", step)
    assert died.returncode == 9, died.stderr
    tags = bundle_tags(tmp_path) if (tmp_path / "reports" / "b").exists() else None
    if step == "between-renames":
        # the one window of the two-rename fallback: no report folder until the next run rolls back
        assert tags is None
    else:
        assert tags in ({"old"}, {"new"}), tags
    # the next run cleans the dead run's temporaries (and rolls back an interrupted swap)
    assert write(tmp_path, "next").returncode == 0
    assert bundle_tags(tmp_path) == {"next"}
    assert temporaries(tmp_path) == []


def test_interrupted_fallback_swap_is_rolled_back(tmp_path):
    assert write(tmp_path, "old").returncode == 0
    assert write(tmp_path, "new", "between-renames").returncode == 9
    clean_stale(tmp_path / "reports")
    assert bundle_tags(tmp_path) == {"old"}


def test_a_live_writer_s_temporaries_are_left_alone(tmp_path):
    mine = tmp_path / f".x.{os.getpid()}.abc.tmp"
    mine.write_text("in progress")
    clean_stale(tmp_path)
    assert mine.exists()


def _limit_file_size():
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)   # a write past the limit fails with EFBIG
    resource.setrlimit(resource.RLIMIT_FSIZE, (60_000, 60_000))


def test_full_disk_is_one_line_and_keeps_the_old_bundle(tmp_path):
    """Regression (issue 7.4): a full disk was an OSError traceback with the netlist
    written and an empty report folder. A file-size limit makes the writes fail as a
    full disk does."""
    args = [script("design-plant"), "--fc", "3500", "--zeta", "0.2", "--no-sim", "--out", str(tmp_path),
            "--name", "p"]
    assert subprocess.run(args, capture_output=True, timeout=120).returncode == 0
    before = {p: p.read_bytes() for p in (tmp_path / "reports" / "p").iterdir()}
    out = subprocess.run(args + ["--amplitude", "3"], capture_output=True, text=True, timeout=120,
                         preexec_fn=_limit_file_size)
    assert out.returncode == 2
    assert len(out.stderr.strip().splitlines()) == 1 and "Traceback" not in out.stderr, out.stderr
    assert "cannot write" in out.stderr
    assert {p: p.read_bytes() for p in (tmp_path / "reports" / "p").iterdir()} == before
    assert (tmp_path / "netlists" / "p.cir").read_text() == before[tmp_path / "reports" / "p" / "p.cir"].decode()
    assert temporaries(tmp_path) == []


def test_directory_in_the_way_is_one_line(tmp_path):
    (tmp_path / "plot.png").mkdir()
    with pytest.raises(DesignError, match="it is a directory"):
        atomic_write(tmp_path / "plot.png", b"x")
    assert list(tmp_path.iterdir()) == [tmp_path / "plot.png"]


def test_old_bundle_with_a_folder_where_a_file_goes_is_replaced(tmp_path):
    """A result.json that is a folder in the old bundle does not stop the new one."""
    assert write(tmp_path, "old").returncode == 0
    rj = tmp_path / "reports" / "b" / "result.json"
    rj.unlink()
    rj.mkdir()
    assert write(tmp_path, "new").returncode == 0
    assert bundle_tags(tmp_path) == {"new"}


def test_netlist_path_that_is_a_directory_is_one_line(tmp_path):
    (tmp_path / "netlists" / "p.cir").mkdir(parents=True)
    out = subprocess.run([script("design-plant"), "--fc", "3500", "--zeta", "0.2", "--no-sim", "--out",
                          str(tmp_path), "--name", "p"], capture_output=True, text=True, timeout=120)
    assert out.returncode == 2 and len(out.stderr.strip().splitlines()) == 1, out.stderr
    assert "p.cir" in out.stderr and "directory" in out.stderr
    assert not (tmp_path / "reports" / "p").exists() and temporaries(tmp_path) == []


def test_publish_into_an_empty_place(tmp_path):
    stage = tmp_path / ".x.new-1-a"
    stage.mkdir()
    (stage / "f").write_text("1")
    publish_folder(stage, tmp_path / "x")
    assert (tmp_path / "x" / "f").read_text() == "1" and not stage.exists()


def _ours(folder) -> list:
    """Our temporaries left in ``folder`` (a staging folder, a moved-aside one, a temporary file or link)."""
    return [p.name for p in Path(folder).iterdir() if p.name.startswith(".")]


@pytest.mark.parametrize("what", ["dangling link", "link to a folder", "link to a file", "file"])
def test_publish_never_swaps_a_link_or_a_file_into_a_stray_temporary(tmp_path, what):
    """publish_folder swapped a dangling link at the target with the new folder, and left the link as
    ``.name.new-PID-*`` (rmtree refuses a link): each is refused in one line, nothing left behind."""
    from designer.core.fileio import new_folder_beside
    (tmp_path / "real").mkdir()
    (tmp_path / "afile").write_text("x")
    target = tmp_path / "out"
    if what == "file":
        target.write_text("mine")
    else:
        target.symlink_to({"dangling link": "nowhere", "link to a folder": "real", "link to a file": "afile"}[what])
    before = os.readlink(target) if target.is_symlink() else target.read_text()
    stage = new_folder_beside(target)
    (stage / "a.txt").write_text("new")
    with pytest.raises(DesignError) as exc:
        publish_folder(stage, target)
    assert "\n" not in str(exc.value) and str(target) in str(exc.value)
    assert _ours(tmp_path) == []
    assert (os.readlink(target) if target.is_symlink() else target.read_text()) == before
    assert sorted(p.name for p in (tmp_path / "real").iterdir()) == []


@pytest.mark.parametrize("what, whole, words", [
    ("dangling link", False, "a symbolic link to nothing (nowhere)"),
    ("link to a file", False, "a symbolic link (to afile)"),
    ("link to a folder", True, "the folder is replaced whole"),
    ("file", False, "it is a file, not a folder"),
    ("fifo", False, "it is a FIFO"),
])
def test_check_output_folder_refuses_before_any_work(tmp_path, what, whole, words):
    from designer.core.fileio import check_output_folder
    (tmp_path / "real").mkdir()
    (tmp_path / "afile").write_text("x")
    target = tmp_path / "out"
    if what == "file":
        target.write_text("mine")
    elif what == "fifo":
        os.mkfifo(target)
    else:
        target.symlink_to({"dangling link": "nowhere", "link to a folder": "real", "link to a file": "afile"}[what])
    with pytest.raises(DesignError) as exc:
        check_output_folder(target, "--out", whole=whole)
    assert words in str(exc.value) and str(exc.value).startswith(f"cannot write --out {target}")


def test_check_output_folder_takes_a_folder_nothing_or_a_link_to_a_folder(tmp_path):
    from designer.core.fileio import check_output_folder
    (tmp_path / "real").mkdir()
    (tmp_path / "link").symlink_to("real")
    for name in ("real", "new", "link"):
        check_output_folder(tmp_path / name, whole=name != "link")
    check_output_folder(tmp_path / "link", whole=False)    # written through
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link", "real"]


def test_remove_tree_unlinks_a_link_and_leaves_its_target(tmp_path):
    from designer.core.fileio import remove_tree
    (tmp_path / "real").mkdir()
    (tmp_path / "real" / "keep").write_text("x")
    (tmp_path / "link").symlink_to("real")
    (tmp_path / "dangling").symlink_to("nowhere")
    remove_tree(tmp_path / "link")
    remove_tree(tmp_path / "dangling")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["real"] and (tmp_path / "real" / "keep").exists()


@pytest.mark.parametrize("what", ["dangling link", "link to a folder", "folder"])
def test_atomic_write_refused_creates_nothing(tmp_path, what):
    """Every kind of refused target: one line, no temporary file, and no parent folder made on the way."""
    (tmp_path / "real").mkdir()
    target = tmp_path / "out.csv"
    if what == "folder":
        target.mkdir()
    else:
        target.symlink_to("nowhere" if what == "dangling link" else "real")
    with pytest.raises(DesignError):
        atomic_write(target, "data")
    assert _ours(tmp_path) == [] and sorted(os.listdir(tmp_path / "real")) == []
    with pytest.raises(DesignError, match="not a valid file name"):   # checked before its folder is made
        atomic_write(tmp_path / "new" / "a\0b.csv", "data")
    assert not (tmp_path / "new").exists()


@pytest.mark.parametrize("what", ["dangling link", "link to a folder"])
def test_link_into_replaces_a_link_there_and_leaves_no_temporary(tmp_path, what):
    """The netlist beside a bundle is our link: one already there (dangling, or to a folder) is replaced
    atomically, what it pointed to untouched, no ``.name.PID.link.tmp`` left."""
    from designer.core.fileio import link_into
    (tmp_path / "real").mkdir()
    (tmp_path / "bundle").mkdir()
    (tmp_path / "bundle" / "x.cir").write_text("deck")
    link = tmp_path / "x.cir"
    link.symlink_to("nowhere" if what == "dangling link" else "real")
    assert link_into(link, tmp_path / "bundle" / "x.cir")
    assert os.readlink(link) == os.path.join("bundle", "x.cir") and link.read_text() == "deck"
    assert _ours(tmp_path) == [] and (tmp_path / "real").is_dir()
