# Every target sets up what it needs: a fresh Debian machine as root needs nothing else.
SHELL := /bin/bash
PY := .venv/bin/python
VENV_STAMP := .venv/.installed
export MPLBACKEND := Agg

.PHONY: setup system-deps lock demo test bench web clean i18n i18n-update

# compileall: the environment may set PYTHONDONTWRITEBYTECODE, and every command would recompile the package
setup: system-deps $(VENV_STAMP)
	@$(PY) -m compileall -q designer

# ngspice (CLI backend) and libngspice (PySpice's shared backend) come from Debian; so do chromium and
# poppler-utils, which the print and screenshot tests of the build sheets use (headless printing to PDF,
# pdfinfo's page count). A bare Debian 12 or 13 has no python3, and its python3 cannot make a venv without
# python3-venv (Debian moves ensurepip there): importing ensurepip is the check that matters.
SYSTEM_PACKAGES := python3 python3-venv ngspice libngspice0-dev chromium poppler-utils
system-deps:
	@if ! command -v python3 >/dev/null 2>&1 || ! python3 -c 'import ensurepip' >/dev/null 2>&1 \
	    || ! command -v ngspice >/dev/null 2>&1 || ! dpkg -s libngspice0-dev >/dev/null 2>&1 \
	    || ! command -v chromium >/dev/null 2>&1 || ! command -v pdfinfo >/dev/null 2>&1; then \
	  echo "Installing $(SYSTEM_PACKAGES) from Debian"; \
	  SUDO=$$( [ "$$(id -u)" = 0 ] || echo sudo ); \
	  $$SUDO apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq $(SYSTEM_PACKAGES); \
	fi

# The dependencies come from the lock (every one pinned, with its hashes, for Python 3.11 to 3.13), the
# package itself without them; a changed lock or pyproject.toml makes the venv anew (--clear), so what is
# installed is exactly the lock, nothing left over from an earlier one. setuptools' "Editable installation"
# notice (information only: a folder named designer/ in the working directory would shadow the package) is
# silenced, so that a set-up that prints anything has something to say.
LOCK := requirements-lock.txt
$(VENV_STAMP): pyproject.toml $(LOCK)
	python3 -m venv --clear .venv
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q --require-hashes -r $(LOCK)
	PYTHONWARNINGS='ignore:Editable installation' $(PY) -m pip install -q --no-deps -e .
	touch $@

# The lock, made anew from pyproject.toml by uv (in a throwaway venv: uv is no dependency of the project) for
# every platform and Python 3.11 to 3.13; the versions already in the lock are kept unless UPGRADE=1 (all to
# the newest) or UPGRADE=name (that one). Then `make setup test` checks the new versions.
lock:
	@set -e; tmp=$$(mktemp -d); trap 'rm -rf "$$tmp"' EXIT; \
	python3 -m venv "$$tmp/uv" && "$$tmp/uv/bin/python" -m pip install -q uv && \
	"$$tmp/uv/bin/uv" pip compile -q pyproject.toml --extra test --universal --python-version 3.11 \
	  --generate-hashes --custom-compile-command "make lock" -o $(LOCK) \
	  $(if $(filter 1,$(UPGRADE)),--upgrade,$(if $(UPGRADE),--upgrade-package $(UPGRADE)))

# The main job: the seed's plant, and PID controllers for it with LM741s (ZN tuning done right,
# the optimiser, and the seed's own final design to show what really happens), and the seed's bench as built
# (trimmed difference amplifier), predicted against what the thesis measured; the plant and the optimised loop
# with a Monte Carlo of their parts' E-series tolerances (the plant's yield within 3.3-3.7 kHz and 55 %
# overshoot, its worst case; the loop's probability of instability, and its worst case on the sheet). Then plants known only as
# models: seed 000's DC motor (Km = 1.25, tau_m = 124.6 ms), a capture simulated in ngspice as a TBS1022 at
# 500 mV/div would record it (10 mV noise, 20 mV LSB), identified, and a PID optimised for the model (AMIGO and
# SIMC divide by the dead time, which the motor has none of; IMC's Ti = tau leaves 2.2 % steady-state error
# through the integrator's leak at these time constants); and a real TBS1022 RC capture (R C = 762 us, output
# only: its input step is the output's settled change, 1.72 V, as an RC's gain is 1), skipped when
# ../shared/ext-captures is not beside this clone (its committed bundle is re-checked by the tests).
EXT_CAPTURES := ../shared/ext-captures
demo: setup
	.venv/bin/design-plant --fc 3500 --zeta 0.2 --monte-carlo 5000 --seed 1 --limit fn_hz=3.3k:3.7k \
	  --limit overshoot_pct=0:55 --worst-case --name plant_fc3500_z0.2 --out .
	.venv/bin/design-pid --plant-fc 3500 --plant-zeta 0.2 --opamp LM741 --name pid_zn_lm741_fc3500_z0.2 --out .
	.venv/bin/design-pid --plant-fc 3500 --plant-zeta 0.2 --opamp LM741 --tuning optimize --target-overshoot 10 \
	  --monte-carlo 1000 --seed 1 --limit phase_margin_deg=25:90 --limit overshoot_pct=0:15 --worst-case \
	  --name pid_optimize_os10_lm741_fc3500_z0.2 --out .
	.venv/bin/design-pid --plant-fc 3500 --plant-zeta 0.2 --opamp LM741 --kp 45 --ti 43.215u --td 10.8037u \
	  --seed-parts --name pid_seed_kp45_lm741_fc3500_z0.2 --out .
	.venv/bin/analyze-pid --plant-r1 805 --plant-r2 1k --plant-c1 10n --plant-c2 220n --opamp LM741 --step 2 \
	  --r3 12k --r4 1.777k --r5 22k --r6 3.3k --r7 14.356k --r8 1.2k --r9 10k --r10 10k --r11 10k --r12 1.026k \
	  --r13 26.048k --r14 2.528k --r15 10k --r16 3.279k --r17 1.716k --r18 9.98k --c3 4.7n --c4 47n \
	  --kp 45 --ti 43.215u --td 10.8037u --name pid_seed_bench_lm741 --out .
	.venv/bin/simulate-capture --plant-tf "K=1.25 tau=124.6m" --step 2 --noise 10m --lsb 20m --seed 0 \
	  --out captures/motor_seed000.csv
	.venv/bin/identify captures/motor_seed000.csv --json > captures/.motor_seed000.identify.json.tmp
	mv captures/.motor_seed000.identify.json.tmp captures/motor_seed000.identify.json
	.venv/bin/design-pid --plant-model captures/motor_seed000.identify.json --tuning optimize \
	  --name pid_motor_seed000 --out .
	.venv/bin/design-filter --family butterworth --order 4 --fc 1k --topology sallen-key --opamp TL072 \
	  --name filter_butterworth_lp4_sk_1k --out .
	.venv/bin/design-filter --family chebyshev --passband 1k --max-loss 0.5 --stopband 2k --min-attenuation 40 \
	  --topology mfb --opamp TL072 --name filter_chebyshev0.5_lp5_mfb_mask1k --out .
	.venv/bin/design-filter --type highpass --family bessel --order 3 --fc 1k --opamp TL072 \
	  --name filter_bessel_hp3_1k --out .
	.venv/bin/design-filter --type bandpass --family butterworth --order 2 --f-low 900 --f-high 1100 --opamp TL072 \
	  --name filter_butterworth_bp2_900-1100 --out .
	@if [ -f $(EXT_CAPTURES)/tom2718_TEK0001.CSV ]; then \
	  set -x; .venv/bin/design-pid --plant-capture $(EXT_CAPTURES)/tom2718_TEK0001.CSV --step-amplitude 1.72 \
	    --name pid_rc_tbs1022 --out .; \
	else \
	  echo "skipping pid_rc_tbs1022: $(EXT_CAPTURES)/tom2718_TEK0001.CSV (the real TBS1022 RC capture) is not" \
	    "beside this clone; the committed reports/pid_rc_tbs1022 is kept"; \
	fi

# the lab's page: http://127.0.0.1:8000/ (designer-web --help: --host, --port, --jobs)
web: setup
	.venv/bin/designer-web

# ruff first (the rules in pyproject.toml: pyflakes and pycodestyle's errors), in seconds, then the tests
test: setup
	$(PY) -m ruff check --quiet --no-cache designer tests benchmarks
	$(PY) -m pytest -q -p no:cacheprovider tests

# the build sheets' Spanish catalogue: every message the code marks (Babel's extractor) translated in
# designer/locale/es/LC_MESSAGES/designer.po; i18n-update adds the missing ones with an empty translation
i18n: setup
	$(PY) -m designer.core.i18n

i18n-update: setup
	$(PY) -m designer.core.i18n --update

bench: setup
	$(PY) benchmarks/run.py

clean:
	rm -rf .venv build *.egg-info .pytest_cache
