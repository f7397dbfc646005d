#!/usr/bin/env bash
# Two hammer tests as a lab hands them over, identified with the lab's facts only (README "Lab
# records, worked"). Usage: run.sh BUILD_DIR OUT_DIR
#   BUILD_DIR  the CMake build directory (default: build)
#   OUT_DIR    where the records and the runs go (default: run/lab-records)
# Each bench is simulated by scole-truth and written as its DAQ writes it (scole-data convert:
# steel.lvm, aluminium.tdms; no noise levels or true values travel with them). Then, per record,
# the lab's three commands: look at the file, (write the scenario: steel.yaml, aluminium.yaml
# here), identify. The steel record is then identified again from a TDMS and a CSV copy.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
build="${1:-build}"
out="${2:-run/lab-records}"
mkdir -p "$out"
for bench in steel:lvm aluminium:tdms; do
  name="${bench%%:*}" ext="${bench##*:}"
  rm -rf "$out/$name-truth" "$out/$name.$ext" "$out/$name"
  # The bench (a Simbody chain) and its DAQ's file.
  "$build/model/scole-truth" -q -s "$here/bench-$name.yaml" -o "$out/$name-truth"
  "$build/io/scole-data" convert -q "$out/$name-truth/truth.csv" -o "$out/$name.$ext"
  # The lab's commands.
  "$build/io/scole-data" info "$out/$name.$ext"
  # (exit 1: not converged, outputs written and marked; check.py reads the verdict)
  "$build/identify/scole-identify" -s "$here/$name.yaml" --data "$out/$name.$ext" -o "$out/$name" || [ $? -eq 1 ]
done
# The steel record as the other formats a lab may hand over (TDMS, CSV, UFF) (bit-identical numbers): the same
# estimates from each.
for ext in tdms csv uff; do
  rm -rf "$out/steel-as-$ext" "$out/steel-as.$ext" "$out/steel-as.$ext.json"
  "$build/io/scole-data" convert -q "$out/steel.lvm" -o "$out/steel-as.$ext"
  "$build/identify/scole-identify" -q -s "$here/steel.yaml" --data "$out/steel-as.$ext" -o "$out/steel-as-$ext"
done
