"""designer.spice.trust: a deck and what it includes, read, checked and inlined by us."""

from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from designer.core.errors import DesignError
from designer.spice.trust import check_deck_text, expand_deck

TITLE = "a deck\n"
BODY = "V1 in 0 1\nR1 in out 1k\nC1 out 0 1n\n.tran 1u 10u\n.end\n"


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def refusal(path, root) -> str:
    with pytest.raises(DesignError) as e:
        expand_deck(path, root)
    msg = str(e.value)
    assert "\n" not in msg
    return msg


def test_includes_and_library_sections_are_inlined_in_place(tmp_path):
    write(tmp_path, "sub/r.inc", "R1 in out\n+ 1k\n.end\n")
    write(tmp_path, "sub/lib.l", ".lib slow\nC1 out 0 1u\n.endl\n.lib fast\n.include c.inc\n.endl fast\n")
    write(tmp_path, "sub/c.inc", "C1 out 0 1n\n")
    deck = write(tmp_path, "d.cir", TITLE + "V1 in 0 1\n.INCLUDE sub/r.inc\n.lib 'sub/lib.l' FAST\n.tran 1u 10u\n.end\n")
    assert expand_deck(deck, tmp_path) == (TITLE + "V1 in 0 1\nR1 in out\n+ 1k\nC1 out 0 1n\n.tran 1u 10u\n.end\n")


def test_an_include_loop_is_refused(tmp_path):
    write(tmp_path, "a.inc", ".include b.inc\n")
    write(tmp_path, "b.inc", ".include a.inc\n")
    assert "nested deeper" in refusal(write(tmp_path, "d.cir", TITLE + ".include a.inc\n" + BODY), tmp_path)


@pytest.mark.parametrize("text, words", [
    (".include nowhere.inc\n", "does not exist"),
    (".lib lib.l\n", "a file and a section"),
    (".lib lib.l nosuch\n", "no section"),
    (".include\n", "one file name"),
])
def test_bad_includes_are_refused_with_their_line(tmp_path, text, words):
    write(tmp_path, "lib.l", ".lib tt\nR9 a 0 1\n.endl\n")
    msg = refusal(write(tmp_path, "d.cir", TITLE + text + BODY), tmp_path)
    assert msg.startswith("d.cir:2: ") and words in msg, msg


def test_a_deck_outside_the_root_is_refused(tmp_path):
    deck = write(tmp_path, "elsewhere/d.cir", TITLE + BODY)
    assert "outside" in refusal(deck, tmp_path / "repo")
    assert expand_deck(deck, None) == TITLE + BODY   # trusted: anywhere


#: every spelling of a control block ngspice 39 accepts, and some it does not (refused all the same)
CONTROL = st.tuples(st.sampled_from(["", " ", "\t", "  \t"]), st.sampled_from([".", "..", ". "]),
                    st.sampled_from(["control", "endc"]).flatmap(
                        lambda w: st.tuples(*(st.sampled_from([c.lower(), c.upper()]) for c in w))),
                    st.sampled_from(["", "x", " now"])).map(lambda t: t[0] + t[1] + "".join(t[2]) + t[3])


@settings(max_examples=200, deadline=None)
@given(spelling=CONTROL, where=st.integers(0, 3), included=st.booleans())
def test_every_spelling_of_a_control_line_is_refused(tmp_path_factory, spelling, where, included):
    folder = tmp_path_factory.mktemp("deck")
    body = BODY.splitlines()
    body.insert(where, spelling)
    if included:
        write(folder, "x.inc", "\n".join(body[:-1]) + "\n")
        deck = write(folder, "d.cir", TITLE + ".include x.inc\n.end\n")
        name = "x.inc"
    else:
        deck = write(folder, "d.cir", TITLE + "\n".join(body) + "\n")
        name = "d.cir"
    msg = refusal(deck, folder)
    assert msg.startswith(name + ":") and ("control" in msg or ".endc" in msg), msg


@settings(max_examples=200, deadline=None)
@given(lines=st.lists(st.sampled_from(["R1 a b 1k", "C1 b 0 1n", "* a comment", "+ 2k", ".param x=1",
                                       ".model d1 d(is=1e-14)", "V1 a 0 1", "* endc is a word", ".ends"]),
                      max_size=12))
def test_a_deck_of_plain_lines_is_given_to_ngspice_unchanged(tmp_path_factory, lines):
    folder = tmp_path_factory.mktemp("deck")
    text = TITLE + "".join(ln + "\n" for ln in lines) + BODY
    assert expand_deck(write(folder, "d.cir", text), folder) == text
    check_deck_text(text)


def test_a_deck_given_as_text_may_include_nothing():
    with pytest.raises(DesignError, match="nothing may be included"):
        check_deck_text(TITLE + ".include x.inc\n" + BODY)
    with pytest.raises(DesignError, match="'\\*#'"):
        check_deck_text(TITLE + "*# shell ls\n" + BODY)
