"""The committed reference build sheets in a real browser: printed to PDF by
headless Chromium on A4 and on Letter (pages counted with poppler's pdfinfo),
and the plant sheet's first screen at 1280x800 showing the schematic, the bill
of materials and the bench settings without scrolling."""

import json
import re
import shutil
import subprocess

import pytest
from helpers import REPORTS

pytestmark = pytest.mark.chromium

PLANT = "plant_fc3500_z0.2"
PIDS = ["pid_zn_lm741_fc3500_z0.2", "pid_optimize_os10_lm741_fc3500_z0.2", "pid_seed_kp45_lm741_fc3500_z0.2",
        "pid_seed_bench_lm741"]
#: the most pages a sheet may print on
LIMITS = {PLANT: 2, **{name: 4 for name in PIDS}}


def chromium(tmp_path, *args, timeout=120):
    exe = shutil.which("chromium")
    assert exe, "chromium is not installed (make setup installs it)"
    # as root Chromium needs --no-sandbox; the rest keeps it from reaching out or syncing
    cmd = [exe, "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-background-networking",
           "--disable-component-update", "--disable-sync", f"--user-data-dir={tmp_path / 'profile'}", *args]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, stdin=subprocess.DEVNULL)


def sheet(name):
    path = REPORTS / name / "build-sheet.html"
    if not path.exists():
        pytest.skip(f"{path} not generated (run make demo)")
    return path.read_text()


def pages(pdf) -> int:
    out = subprocess.run(["pdfinfo", str(pdf)], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    return int(re.search(r"^Pages:\s+(\d+)", out.stdout, re.M).group(1))


@pytest.mark.parametrize("paper", ["A4", "letter"])
@pytest.mark.parametrize("name", list(LIMITS))
def test_a_reference_sheet_prints_within_its_pages(name, paper, tmp_path):
    html = sheet(name)
    # the paper as a print dialog would choose it; the sheet's own @page rule sets the margins
    page = tmp_path / f"{paper}.html"
    page.write_text(html.replace("<style>", f"<style>@page{{size:{paper}}}", 1))
    pdf = tmp_path / f"{paper}.pdf"
    out = chromium(tmp_path, f"--print-to-pdf={pdf}", "--no-pdf-header-footer", page.as_uri())
    assert pdf.exists() and pdf.stat().st_size > 0, out.stderr[-2000:]
    n = pages(pdf)
    assert 1 <= n <= LIMITS[name], f"{name} prints on {n} {paper} pages"
    size = subprocess.run(["pdfinfo", str(pdf)], capture_output=True, text=True).stdout
    assert ("A4" in size) if paper == "A4" else ("letter" in size), size


def test_the_sheet_css_prints_well():
    html = sheet(PLANT)
    for rule in ("@page", "thead{display:table-header-group}", "tr{break-inside:avoid}", "white-space:nowrap"):
        assert rule in html, rule


MEASURE = """<script>
window.addEventListener('load', () => {
  const r = s => { const e = document.querySelector(s); if (!e) return null;
                   const b = e.getBoundingClientRect(); return [b.left, b.top, b.right, b.bottom]; };
  const tables = [...document.querySelectorAll('table')];
  const find = t => tables.find(x => x.querySelector('th') && x.querySelector('th').textContent === t);
  const box = e => { if (!e) return null; const b = e.getBoundingClientRect(); return [b.left, b.top, b.right, b.bottom]; };
  const out = {schematic: r('.fig svg'), bom: box(find('Ref')), settings: box(find('set')),
               width: window.innerWidth, height: window.innerHeight};
  const pre = document.createElement('pre'); pre.id = 'measured'; pre.textContent = JSON.stringify(out);
  document.body.appendChild(pre);
});
</script>"""


def test_the_first_screen_shows_schematic_bill_of_materials_and_bench_settings(tmp_path):
    html = sheet(PLANT)
    page = tmp_path / "measure.html"
    page.write_text(html.replace("</body>", MEASURE + "</body>", 1))
    out = chromium(tmp_path, "--window-size=1280,800", "--hide-scrollbars", "--dump-dom", page.as_uri())
    found = re.search(r"<pre id=\"measured\">(.*?)</pre>", out.stdout, re.S)
    assert found, out.stderr[-2000:]
    m = json.loads(found.group(1).replace("&quot;", '"'))
    assert m["width"] == 1280   # (--dump-dom's viewport is shorter than the screenshot's 800)
    for key in ("schematic", "bom", "settings"):
        left, top, right, bottom = m[key]
        assert 0 <= left and right <= 1280 and 0 <= top and bottom <= 800, (key, m[key])
        assert right - left > 200 and bottom - top > 80, (key, m[key])
    # the screenshot itself: a 1280x800 PNG, as the README shows it
    shot = tmp_path / "first-screen.png"
    chromium(tmp_path, "--window-size=1280,800", "--hide-scrollbars", f"--screenshot={shot}",
             (REPORTS / PLANT / "build-sheet.html").as_uri())
    data = shot.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    assert int.from_bytes(data[16:20], "big") == 1280 and int.from_bytes(data[20:24], "big") == 800
