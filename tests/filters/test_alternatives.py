"""The runner-up part sets (designer.filters.alternatives): the least objectives of every combination of
the design's own candidates, the joint choice first, each one's figures recomputed from its parts."""

import itertools
import math

import numpy as np
import pytest

from designer.filters import FilterSpec
from designer.filters.alternatives import design_alternatives
from designer.filters.design import design, with_choice
from designer.filters.joint import PENALTY, objective


@pytest.mark.parametrize("kw", [dict(order=4, fc_hz=1e3, opamp="TL072"),
                                dict(family="chebyshev", passband_hz=1e3, max_loss_db=1.0, stopband_hz=3e3,
                                     min_attenuation_db=30.0, opamp="TL072"),
                                dict(family="bessel", passband_hz=1e3, max_loss_db=3, stopband_hz=5e3,
                                     min_attenuation_db=40, max_delay_error_pct=0.15, delay_to_hz=500,
                                     r_series="E12", c_series="E12", opamp="TL072")])
def test_alternatives_are_the_enumerations_least(kw):
    d = design(FilterSpec(**kw))
    search, limits, n_dev = d.problem
    got = design_alternatives(d, 6)
    every = sorted(objective(search, ch, limits, n_dev) for ch in itertools.product(*(range(len(e)) for e in search)))
    assert [a.objective_db for a in got] == pytest.approx(every[:6], abs=1e-12)
    assert [a.rank for a in got] == list(range(1, 7))
    # the first is the joint choice: its deviation the design's
    assert got[0].error_db == pytest.approx(d.figures["error_joint_db"], abs=1e-12)
    assert len({a.choice for a in got}) == 6
    for a in got:
        # the parts as built are the candidates', every stage's, named Ri01..
        moved = with_choice(d, list(a.choice))
        want = {}
        for st in moved.stages:
            want.update({f"{r[0]}{st.number}0{r[1:]}": v for r, v in st.values.items()})
        assert a.parts == want
        assert a.error_db == pytest.approx(objective([st.errors for st in d.stages], a.choice), abs=1e-12)
        assert a.error_db <= a.objective_db + 1e-12
        if limits is None:
            assert a.violation is None and a.objective_db == pytest.approx(a.error_db, abs=1e-12)
        else:
            # the objective: the deviation, or the worst limit's violation weighted, the larger
            assert a.violation >= 0.0
            assert a.objective_db == pytest.approx(max(a.error_db, PENALTY * a.violation), abs=1e-9)


def test_a_mask_alternative_that_meets_it_is_the_design_meeting_it():
    """With a mask, a set listed as meeting it (violation 0) meets it on its own analytic response."""
    d = design(FilterSpec(family="chebyshev", passband_hz=1e3, max_loss_db=1.0, stopband_hz=3e3,
                          min_attenuation_db=30.0, opamp="TL072"))
    for a in design_alternatives(d, 5):
        f = with_choice(d, list(a.choice)).figures
        met = f["mask_passband_margin_db"] >= -1e-9 and f["mask_stopband_margin_db"] >= -1e-9
        assert met == (a.violation <= 1e-9)
        assert a.to_dict()["parts"] == a.parts and math.isfinite(a.to_dict()["error_db"])


def test_fewer_combinations_than_asked_lists_them_all():
    d = design(FilterSpec(order=1, fc_hz=1e3))
    n = int(np.prod([len(st.candidates) for st in d.stages]))
    got = design_alternatives(d, n + 5)
    assert len(got) == n and got[0].choice == tuple(st.chosen for st in d.stages)
