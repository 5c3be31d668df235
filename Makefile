# RTMU: two commands get you going on Debian 12 / Ubuntu: `make demo` and `make test`.
# Every target first runs scripts/setup.sh, which installs what is missing (apt packages, .venv,
# the project) and otherwise returns in a fraction of a second.

VENV := .venv
BIN := $(VENV)/bin

.PHONY: setup demo test lint format bench help

help:
	@echo "make demo   run RTMU against the bundled robot simulator"
	@echo "make test   lint (ruff check, ruff format --check) and the whole pytest suite"
	@echo "make lint   only the lint half of 'make test'"
	@echo "make bench  run the benchmarks, print a table, write bench/results.json"
	@echo "make format reformat and auto-fix with ruff"
	@echo "make setup  only install what is missing (every target does this first)"

setup:
	@bash scripts/setup.sh

demo: setup
	$(BIN)/rtmu --demo

# All three checks run even when one fails, so one run shows every problem; the target fails if any did.
test: setup
	@status=0; \
	echo "== ruff check"; $(BIN)/ruff check . || status=1; \
	echo "== ruff format --check"; $(BIN)/ruff format --check . || status=1; \
	echo "== pytest"; $(BIN)/pytest || status=1; \
	if [ $$status -ne 0 ]; then echo "make test: FAILED (see above)"; fi; \
	exit $$status

lint: setup
	@status=0; \
	$(BIN)/ruff check . || status=1; \
	$(BIN)/ruff format --check . || status=1; \
	exit $$status

format: setup
	$(BIN)/ruff format .
	$(BIN)/ruff check --fix .

bench: setup
	$(BIN)/python -m bench.run
