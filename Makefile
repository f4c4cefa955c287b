# The README's two commands are `make run` and `make test`; each sets everything up first.
.PHONY: setup run test test-slow bench clean

setup:
	@bash tools/setup.sh

run: setup
	.venv/bin/tg-drake run scenarios/default.yaml --out out/default

test: setup
	.venv/bin/python -m pytest -q

test-slow: setup
	.venv/bin/python -m pytest -q -m slow

bench: setup
	.venv/bin/tg-drake bench --out out/bench.json
