# clothwind: the two commands of the README.
#   make run   install dependencies, build (Release), run the main job on the embedded default
#   make test  install dependencies, build, run every unit and integration test, print one summary
BUILD ?= build
export CLOTHWIND_BUILD := $(abspath $(BUILD))

.PHONY: run test build deps clean
run: build
	scripts/run-main $(BUILD)

test: build
	scripts/run-tests $(BUILD)

build: deps
	scripts/build $(BUILD)

deps:
	@scripts/install-deps

clean:
	rm -rf $(BUILD) $(BUILD).configure.log
