"""The sheets' plots in their language (designer/report/plots.py and the plot functions of the plant, PID and
filter sheets; issue 29): every text matplotlib draws (axis labels, tick labels, legends, titles, marks), read
from the Figure as it is saved, has no English word in Spanish and writes its numbers with a decimal comma; in
English the same texts are the code's own."""

import re

import pytest
from helpers import foreign, vocabulary
from matplotlib.figure import Figure
from matplotlib.text import Text

from designer.core.i18n import catalogue, language
from designer.filters import report as filter_report
from designer.filters.design import design as design_filter
from designer.filters.spec import FilterSpec
from designer.pid import report as pid_report
from designer.pid.design import PidSpec, design_model_pid, design_pid
from designer.plant import report as plant_report
from designer.plant.design import design_plant
from designer.plant.spec import PlantSpec
from designer.report.plots import histogram_plot

#: a number written with a decimal point (a tick label, a legend's value)
DECIMAL_POINT = re.compile(r"(?<![\w.])\d+\.\d+\b(?!\.\d)")
DECIMAL_COMMA = re.compile(r"(?<![\w,])\d+,\d+\b")


@pytest.fixture
def drawn(monkeypatch):
    """The texts of every figure saved while the test runs (one list per figure), as drawn: the tick labels
    are matplotlib's once the figure is rendered."""
    figures = []
    save = Figure.savefig

    def recording(fig, *args, **kw):
        out = save(fig, *args, **kw)
        figures.append([t.get_text().strip() for t in fig.findobj(Text) if t.get_visible() and t.get_text().strip()])
        return out
    monkeypatch.setattr(Figure, "savefig", recording)
    return figures


@pytest.fixture(scope="module")
def designs():
    """A plant, a seed PID, a model-plant PID and a filter with a group-delay target (no SPICE: the plots'
    words are the same, and the analytic curves carry the numbers)."""
    plant = design_plant(PlantSpec(fc_hz=3500, zeta=0.2), simulate=False)
    pid = design_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2), simulate=False)
    model = design_model_pid(PidSpec(plant_tf="K=2 tau=1m theta=200u", tuning="amigo"), simulate=False)
    flt = filter_report.sheet_of(design_filter(FilterSpec(family="bessel", passband_hz=1e3, max_loss_db=3,
                                                          stopband_hz=10e3, min_attenuation_db=30,
                                                          max_delay_error_pct=5, delay_to_hz=500), simulate=False))
    return plant, pid, model, flt


def _draw_all(designs) -> None:
    plant, pid, model, flt = designs
    for _name, draw in plant_report.PLOTS:
        draw(plant)
    for _name, draw in pid_report.PLOTS:
        draw(pid)
    for _name, draw in pid_report.MODEL_PLOTS:
        draw(model)
    for draw in (filter_report.bode_png, filter_report.time_png, filter_report.group_delay_png):
        draw(flt)
    histogram_plot([1.5e3, 1.6e3, 1.7e3, 1.65e3], "fn_hz", nominal=1.6e3, lo=1.55e3, hi=1.75e3)


def test_every_plot_of_the_spanish_sheets_shows_no_english_word_and_decimal_commas(designs, drawn):
    with language("es"):
        _draw_all(designs)
    assert len(drawn) == 2 + 4 + 4 + 3 + 1
    english, _spanish = vocabulary()
    texts = [t for fig in drawn for t in fig]
    assert foreign(texts, english) == []
    assert [t for t in texts if DECIMAL_POINT.search(t)] == []
    assert sum(len(DECIMAL_COMMA.findall(t)) for t in texts) > 20   # tick labels, margins, legends' values
    es = catalogue("es")
    for word in ("gain (dB)", "phase (deg)", "frequency (Hz)", "time after the step", "builds"):
        assert any(es[word] in t for t in texts), word
    assert any(t.startswith(es["PM {pm} deg"].split("{")[0]) for t in texts)


def test_the_english_plots_keep_the_code_s_words(designs, drawn):
    _draw_all(designs)
    texts = [t for fig in drawn for t in fig]
    _english, spanish = vocabulary()
    assert foreign(texts, spanish) == []
    assert [t for t in texts if DECIMAL_COMMA.search(t)] == []
    for word in ("gain (dB)", "phase (deg)", "frequency (Hz)", "builds"):
        assert word in texts, word
