# The two commands of the README. Both set up .venv/ first (quick when it is up to date).
.PHONY: demo test setup

demo: setup
	.venv/bin/easynav demo

test: setup
	.venv/bin/python tools/run_tests.py

setup:
	bash tools/setup.sh
