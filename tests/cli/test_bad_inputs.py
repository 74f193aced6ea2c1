"""The corpus of bad inputs (tests/corpus/bad_inputs.tsv): every command, every
defect class found by hostile-user sessions. Each case must end with its exit
status and, on a refusal, exactly one line on stderr containing the expected
text; no traceback, no warning, and nothing written to the output folder."""

import shlex
from pathlib import Path

import pytest

from designer.cli.check import check_design_main
from designer.cli.identify import identify_freq_main, identify_main
from designer.cli.pid import analyze_pid_main, design_pid_main
from designer.cli.plant import analyze_plant_main, design_plant_main

HERE = Path(__file__).resolve().parent
CORPUS = HERE / "corpus" / "bad_inputs.tsv"
FILES = HERE / "corpus" / "files"
MAINS = {"design-plant": design_plant_main, "analyze-plant": analyze_plant_main, "design-pid": design_pid_main,
         "identify": identify_main, "identify-freq": identify_freq_main, "analyze-pid": analyze_pid_main,
         "check-design": check_design_main}


def cases():
    for n, line in enumerate(CORPUS.read_text().splitlines(), 1):
        if line.strip() and not line.startswith("#"):
            cmd, args, status, needle = (line.split("\t") + [""])[:4]
            yield pytest.param(cmd, args, int(status), needle, id=f"{n}:{cmd} {args}"[:90])


@pytest.fixture(scope="module")
def big(tmp_path_factory):
    """A 300 MiB file of zeros (sparse: costs no disk), above the capture size limit."""
    path = tmp_path_factory.mktemp("big") / "big.csv"
    with open(path, "wb") as fh:
        fh.truncate(300 * 2 ** 20)
    return path


@pytest.mark.parametrize("cmd,args,status,needle", list(cases()))
def test_bad_input(cmd, args, status, needle, tmp_path, capsys, request):
    out = tmp_path / "out"
    out.mkdir()
    words = [w.encode().decode("unicode_escape") for w in shlex.split(args)]
    subst = {"{files}": str(FILES), "{out}": str(out)}
    if "{big}" in args:
        subst["{big}"] = str(request.getfixturevalue("big"))
    for key, value in subst.items():
        words = [w.replace(key, value) for w in words]
    got = MAINS[cmd](words)
    err = capsys.readouterr().err
    assert got == status, err
    assert "Traceback" not in err and "Warning" not in err and "np.float64" not in err
    if status == 2:
        lines = err.strip().splitlines()
        assert len(lines) == 1, err
        assert needle in lines[0], lines[0]
        assert list(out.iterdir()) == []
