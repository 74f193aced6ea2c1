"""The README's screenshots of the web page: a designer-web on a free local port, each page
as a student uses it, headless Debian chromium (Playwright). Run from the repository:
``.venv/bin/python docs/web/screenshots.py``; writes docs/web/<page>.png."""

import shutil
import signal
import subprocess
import sys
from pathlib import Path

from playwright.sync_api import sync_playwright

HERE = Path(__file__).parent
ROOT = HERE.parent.parent
CAPTURE = ROOT / "tests" / "fixtures" / "identify" / "tektronix_mso.csv"
SPEC = """name: lab3-plant
kind: plant
target: {fc: 3.5k, zeta: 0.2}
opamp: [LM741, TL072]
checks:
  fn_hz: {typ: 3500, min: "-2%", max: "+2%"}
  overshoot_pct: {max: 55}
  zeta_opamp: {min: 0.15, fail: false}
"""


def wait_answer(pg, before=0, timeout=120000):
    pg.wait_for_function("n => +(document.body.dataset.answers || 0) > n", arg=before, timeout=timeout)


def main() -> int:
    server = subprocess.Popen([sys.executable, "-m", "designer.web.server", "--port", "0"], stdout=subprocess.PIPE,
                              text=True)
    try:
        url = server.stdout.readline().split("serving on ")[1].split()[0].rstrip("/")
        with sync_playwright() as p:
            b = p.chromium.launch(executable_path=shutil.which("chromium"), headless=True)
            pg = b.new_page(viewport={"width": 1400, "height": 1100})
            pg.goto(url + "/plant")
            wait_answer(pg)
            pg.screenshot(path=str(HERE / "plant.png"))
            pg.goto(url + "/identify")
            pg.set_input_files("#file", str(CAPTURE))
            wait_answer(pg)
            pg.screenshot(path=str(HERE / "identify.png"))
            pg.click("#topid")
            pg.wait_for_url("**/pid?plant=identify")
            wait_answer(pg)
            pg.screenshot(path=str(HERE / "pid.png"))
            pg.goto(url + "/check")
            pg.fill("#spec", SPEC)
            pg.click("#run")
            wait_answer(pg)
            pg.screenshot(path=str(HERE / "check.png"))
            b.close()
    finally:
        server.send_signal(signal.SIGINT)
        server.wait(30)
        server.stdout.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
