# Thin wrapper: the two commands of the README, and the pieces they are made of.
BUILD ?= build
JOBS  ?= 2
OUT   ?= run

.PHONY: run test deps build bench slow clean

run: build
	$(BUILD)/identify/scole-identify --scenario paper-beam-1 --out $(OUT)/paper-beam-1

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS) -LE slow

slow: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS) -L slow

bench: build
	$(BUILD)/identify/scole-identify-bench

deps:
	bash .ci/install-deps

build: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release
	cmake --build $(BUILD) -j $(JOBS)

clean:
	rm -rf $(BUILD)
