"""What the spec tests share (tests/check/test_spec.py, test_sections.py, test_yamldoc.py): a spec file
written from text, a deck with two ``.meas`` lines, and a spec's refusal, which is one line."""

import textwrap
from pathlib import Path

import pytest

from designer.check.spec import load_spec
from designer.core.errors import DesignError

DECK = "deck\nV1 in 0 PULSE(0 1 1u 1n 1n 1 2)\nR1 in out 1k\nC1 out 0 1n\n.tran 10n 20u\n" \
       ".meas tran vmax MAX v(out)\n.meas tran T_Rise WHEN v(out)=0.5 RISE=1\n.end\n"


def write(tmp_path, text, name="spec.yaml") -> Path:
    path = tmp_path / name
    path.write_text(textwrap.dedent(text))
    return path


def refusal(path, **kw) -> str:
    with pytest.raises(DesignError) as info:
        load_spec(path, **kw)
    msg = str(info.value)
    assert "\n" not in msg
    return msg
