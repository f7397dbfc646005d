# Thin wrapper: the two commands of the README, and the pieces they are made of.
BUILD ?= build
JOBS  ?= 2
OUT   ?= run
SCENARIO ?= paper-scole-1

.PHONY: run test deps build bench slow clean fuzz asan

FUZZ_BUILD   ?= build-fuzz
ASAN_BUILD   ?= build-asan
FUZZ_SECONDS ?= 60

# Main job: a Simbody truth trajectory, the FE identifier on that data file, then the cross-check
# of the two (modes, trajectories, identification at n, 2n, 4n segments) and its summary.
run: build
	$(BUILD)/model/scole-truth --scenario $(SCENARIO) --out $(OUT)/$(SCENARIO)/truth
	$(BUILD)/identify/scole-identify --scenario $(SCENARIO) --data $(OUT)/$(SCENARIO)/truth/truth.csv --out $(OUT)/$(SCENARIO)/identify
	$(BUILD)/crosscheck/scole-crosscheck all --scenario $(SCENARIO) --out $(OUT)/$(SCENARIO)/crosscheck

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS) -LE slow

slow: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS) -L slow

bench: build
	$(BUILD)/identify/scole-identify-bench
	$(BUILD)/identify/scole-nonlinear-bench
	$(BUILD)/identify/scole-experiments-bench
	$(BUILD)/crosscheck/scole-crosscheck-bench
	$(BUILD)/identify/scole-sections-bench --part 4

deps:
	bash .ci/install-deps

build: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release
	cmake --build $(BUILD) -j $(JOBS)

# libFuzzer harnesses of the io loaders (clang, ASan + UBSan), each for FUZZ_SECONDS on a
# build-directory copy of tests/fuzz/corpus/; reproducers go to $(FUZZ_BUILD)/tests/fuzz/artifacts/.
fuzz:
	bash .ci/install-deps clang libclang-rt-dev
	cmake -S . -B $(FUZZ_BUILD) -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
	  -DSCOLEID_FUZZ=ON -DSCOLEID_FUZZ_SECONDS=$(FUZZ_SECONDS)
	cmake --build $(FUZZ_BUILD) -j $(JOBS)
	cd $(FUZZ_BUILD) && ctest --output-on-failure -L fuzz

# The default suite under AddressSanitizer + UBSan (the mismatch suite aside: its Simbody and
# identification runs take an hour under the sanitizers); any report (leaks included) fails its test.
# Without MPI: Open MPI's own allocations at exit would read as leaks.
asan: deps
	cmake -S . -B $(ASAN_BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSCOLEID_SANITIZE=ON -DSCOLEID_WITH_MPI=OFF
	cmake --build $(ASAN_BUILD) -j $(JOBS)
	cd $(ASAN_BUILD) && ASAN_OPTIONS=detect_leaks=1 \
	  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	  ctest --output-on-failure -j $(JOBS) -LE 'slow|fuzz|mismatch'

clean:
	rm -rf $(BUILD)
