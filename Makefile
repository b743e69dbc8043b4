# Two entry points (see README): `make report` and `make test`.
PYTHON ?= $(shell command -v python3.11 || command -v python3)
VENV := .venv
BIN := $(VENV)/bin
OUT ?= results

.PHONY: install report test test-slow clean

$(BIN)/.installed: pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[test,drake]"
	touch $@

install: $(BIN)/.installed

# a study whose gate fails (exit 1) is still drawn: the report shows the failure;
# out-of-the-box before run: the site run writes links its page and gives each mechanism its row
report: install
	-$(BIN)/mbfidelity convergence --out $(OUT) > /dev/null
	$(BIN)/mbfidelity strutt --grid 100 --out $(OUT) > /dev/null
	$(BIN)/mbfidelity beams --out $(OUT) > /dev/null
	-$(BIN)/mbfidelity discretization massive_spring --sim mujoco --sim pybullet --sim exudyn --sim pymunk --out $(OUT) > /dev/null
	-$(BIN)/mbfidelity discretization beam_with_block --sim mujoco --sim pybullet --sim exudyn --sim pymunk --out $(OUT) > /dev/null
	$(BIN)/mbfidelity errata --out $(OUT) > /dev/null
	$(BIN)/mbfidelity out-of-the-box --out $(OUT) > /dev/null
	$(BIN)/mbfidelity run --out $(OUT)
	@echo "errata:  $(OUT)/errata.html"

test: install
	$(BIN)/python -m pytest -q

test-slow: install
	$(BIN)/python -m pytest -q -m slow

clean:
	rm -rf $(VENV) $(OUT)
