# The two commands of the README. Both set up .venv/ first (quick when it is up to date).
.PHONY: demo test setup bench matrix soak dist isolated

demo: setup
	.venv/bin/easynav demo

test: setup
	.venv/bin/python tools/run_tests.py

# Every benchmark script of every package, one table: docs/benchmarks.md (tens of minutes).
bench: setup
	.venv/bin/python tools/run_benchmarks.py

# An hour of simulated patrol on the warehouse, faster than real time: docs/soak.md (~25 min).
soak: setup
	.venv/bin/python benchmarks/soak.py

# Every compatible plugin combination in every world: docs/matrix.md (long: a mission per row),
# at twice real time (one mission then takes the two cores of a small machine).
matrix: setup
	.venv/bin/python tests/matrix/run_matrix.py --speed-up 2

# A wheel and an sdist of every distribution, in dist/.
dist: setup
	.venv/bin/python tools/release.py build

# Every distribution installed alone in a fresh venv, its tests against the lowest and the
# highest sibling versions its ranges allow (long).
isolated: setup
	.venv/bin/python tools/release.py isolated-all

setup:
	bash tools/setup.sh
