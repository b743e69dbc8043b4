# Two entry points (see README): `make report` and `make test`.
PYTHON ?= $(shell command -v python3.11 || command -v python3)
VENV := .venv
BIN := $(VENV)/bin
OUT ?= results
POWER_RECORD := benchmarks/records/power_study.json.gz

.PHONY: install report power test test-slow clean

$(BIN)/.installed: pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[test,drake]"
	touch $@

install: $(BIN)/.installed

# a study whose gate fails (exit 1) is still drawn: the report shows the failure;
# power before run: it writes power.json and out_of_the_box.json from the same runs (each
# default is switched on once), and the site run links both pages and gives each mechanism
# its out-of-the-box row; the report lends the recorded study's readings made with the
# installed engines (`make power` makes every reading again and records them)
report: install
	-$(BIN)/mbfidelity convergence --out $(OUT) > /dev/null
	$(BIN)/mbfidelity strutt --grid 100 --out $(OUT) > /dev/null
	$(BIN)/mbfidelity beams --out $(OUT) > /dev/null
	-$(BIN)/mbfidelity discretization massive_spring --sim mujoco --sim pybullet --sim exudyn --sim pymunk --out $(OUT) > /dev/null
	-$(BIN)/mbfidelity discretization beam_with_block --sim mujoco --sim pybullet --sim exudyn --sim pymunk --out $(OUT) > /dev/null
	$(BIN)/mbfidelity errata --out $(OUT) > /dev/null
	$(BIN)/mbfidelity power --record $(POWER_RECORD) --out $(OUT) > /dev/null
	$(BIN)/mbfidelity run --out $(OUT)
	@echo "errata:  $(OUT)/errata.html"

# the whole power study made again (every reading; its readings in the persistent cache are
# still taken), then recorded for the reports that follow
power: install
	$(BIN)/mbfidelity power --out $(OUT)
	$(BIN)/python benchmarks/power_record.py $(OUT) --record benchmarks/records/power.json \
		--study $(POWER_RECORD)

test: install
	$(BIN)/python -m pytest -q

test-slow: install
	$(BIN)/python -m pytest -q -m slow

clean:
	rm -rf $(VENV) $(OUT)
