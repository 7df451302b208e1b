# Shortcuts for the project's scripts.
.PHONY: deps build test experiment
deps:
	scripts/install_deps.sh
build:
	scripts/build.sh -j2
test:
	tests/run_all.sh
experiment:
	scripts/run_experiment.sh
