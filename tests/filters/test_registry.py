"""The registry: names to topology instances, an unknown name refused in one line."""

import pytest

from designer.core.errors import DesignError
from designer.filters import REGISTRY, Topology, get, names, register
from designer.filters.rc_lowpass import RcLowPass


def test_every_section_of_the_first_slice_is_registered_under_its_own_name():
    # the first slice, in registration order; a section added later goes after it (and needs no edit here)
    assert names()[:10] == ["sallen-key-lowpass", "sallen-key-lowpass-gain", "sallen-key-highpass",
                            "sallen-key-highpass-gain", "mfb-lowpass", "mfb-highpass", "mfb-bandpass", "rc-lowpass",
                            "rc-highpass", "inverting-lowpass"]
    for name, topology in REGISTRY.items():
        assert isinstance(topology, Topology) and topology.name == name and get(name) is topology
        assert len(set(topology.designators)) == len(topology.designators)
        assert all(p.kind in "RC" and p.ref[0] == p.kind and p.role for p in topology.parts)


def test_get_ignores_case_and_spaces():
    assert get("  MFB-LowPass ") is REGISTRY["mfb-lowpass"]


@pytest.mark.parametrize("typo, closest", [("mfb-lowpas", "mfb-lowpass"), ("sallenkey-highpass", "sallen-key-highpass"),
                                           ("rc-hipass", "rc-highpass")])
def test_an_unknown_name_is_one_line_listing_the_registered_and_the_closest(typo, closest):
    with pytest.raises(DesignError) as err:
        get(typo)
    msg = str(err.value)
    assert "\n" not in msg and msg.startswith("topology: unknown topology")
    assert all(n in msg for n in names()) and msg.endswith(f"did you mean {closest}?")
    assert err.value.param == "topology"


def test_a_taken_name_cannot_be_registered_twice():
    with pytest.raises(ValueError, match="already registered"):
        register(RcLowPass())
    assert list(REGISTRY).count("rc-lowpass") == 1
