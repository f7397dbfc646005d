# Thin wrapper: the two commands of the README, and the pieces they are made of.
BUILD ?= build
JOBS  ?= 2
OUT   ?= run
SCENARIO ?= paper-scole-1

.PHONY: run test deps build bench slow clean

# Main job: a Simbody truth trajectory, then the FE identifier on that data file.
run: build
	$(BUILD)/model/scole-truth --scenario $(SCENARIO) --out $(OUT)/$(SCENARIO)/truth
	$(BUILD)/identify/scole-identify --scenario $(SCENARIO) --data $(OUT)/$(SCENARIO)/truth/truth.csv --out $(OUT)/$(SCENARIO)/identify

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
