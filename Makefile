# The two commands of the README. Both set up .venv/ first (quick when it is up to date).
.PHONY: demo test setup bench

demo: setup
	.venv/bin/easynav demo

test: setup
	.venv/bin/python tools/run_tests.py

# Every benchmark script of every package, one table: docs/benchmarks.md (tens of minutes).
bench: setup
	.venv/bin/python tools/run_benchmarks.py

setup:
	bash tools/setup.sh
