# The two entry points of README.md; both set the machine up first (idempotent).
# The suite runs on every core (pytest-xdist): shared artefacts are built once under a file lock
# (tests/artefacts.py), and tests marked `quiet` run while the other workers wait. One worker
# per core: on the 2-core AMD host of 2026-12-07 (fresh clones, quiet, four runs in turn)
# 2 workers took 840 and 983 s, 3 took 1,000 and 1,075 s (sums of test times 1,493-1,707 s
# against 2,518-2,754: a third worker's contention costs more than the gaps it fills); on the
# Intel host of 2026-12-06, 3 workers had won (484-532 s against 531-578 s).
# `make test WORKERS=3` still runs three.
.PHONY: setup demo test test-fast test-random test-coverage lint

WORKERS ?= $(shell nproc)
PYTEST = .venv/bin/python -m pytest -n $(WORKERS) --dist worksteal

setup:
	bash scripts/setup.sh

demo: setup
	bash scripts/demo.sh out/demo

test: setup
	$(PYTEST) -q

# the inner loop: everything but the tests marked `slow` (each says why it is)
test-fast: setup
	$(PYTEST) -q -m "not slow"

# the suite in a shuffled order: pytest -p randomly --randomly-seed=N repeats the order of seed N
test-random: setup
	$(PYTEST) -q -p randomly

# branch coverage of sgdata, seannet and the CLI, in-process code only
test-coverage: setup
	$(PYTEST) -q --cov=sgdata --cov=seannet --cov=cli --cov-branch --cov-report=term:skip-covered

lint: setup
	.venv/bin/ruff check . && .venv/bin/ruff format --check .
