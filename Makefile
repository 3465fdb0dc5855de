# clothwind: the two commands of the README.
#   make run   install dependencies, build (Release), run the main job on the embedded default
#   make test  install dependencies, build, run every unit and integration test, print one summary
BUILD ?= build
# make splits words at spaces: BUILD="my build" ran the scripts on two folders, and `make clean`
# removed ./build and ./my. A path with a space is refused; scripts/build takes one as it is.
ifneq ($(words $(BUILD)),1)
$(error BUILD="$(BUILD)": a build folder whose path has a space (or is empty) cannot pass through make; run scripts/build, scripts/run-tests or scripts/run-main with it instead)
endif
export CLOTHWIND_BUILD := $(abspath $(BUILD))

.PHONY: run test build deps clean
run: build
	scripts/run-main "$(BUILD)"

test: build
	scripts/run-tests "$(BUILD)"

build: deps
	scripts/build "$(BUILD)"

deps:
	@scripts/install-deps

clean:
	rm -rf -- "$(BUILD)" "$(BUILD).configure.log"
