# The two entry points of README.md; both set the machine up first (idempotent).
# The suite runs on every core (pytest-xdist): shared artefacts are built once under a file lock
# (tests/artefacts.py), and tests marked `quiet` run while the other workers wait. One worker
# more than cores: a worker waits part of its time (on a lock, a server, a subprocess), and
# the extra one fills those gaps (2 cores: 3 workers 484-532 s, 2 workers 531-578 s).
.PHONY: setup demo test test-fast test-random test-coverage lint

WORKERS ?= $(shell echo $$(( $$(nproc) + 1 )))
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
