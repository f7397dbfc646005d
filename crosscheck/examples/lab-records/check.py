"""Checks run.sh's identifications against the benches they were recorded on.

Usage: check.py OUT_DIR BUILD_DIR
Per record: converged; EI and rho_A within 1 % of the bench, zeta within 10 %; every parameter's
interval covering the bench's value; the first three identified modes' frequencies and damping
ratios within their intervals of the bench chain's own modes (scole-crosscheck modes, the
bench's chain linearised at rest). The steel record from its TDMS, CSV and UFF copies: the same
estimates within 1e-9. Prints one line per check; exits 1 if any fails.
"""
import json
import os
import subprocess
import sys

import yaml  # python3-yaml, a dependency of the Python tests

here = os.path.dirname(os.path.abspath(__file__))
out, build = sys.argv[1], sys.argv[2]
failed = []
def check(ok, what):
    print(("ok      " if ok else "FAILED  ") + what)
    if not ok:
        failed.append(what)


for name in ("steel", "aluminium"):
    bench = yaml.safe_load(open(os.path.join(here, "bench-%s.yaml" % name)))
    truth = {k: bench["beam"][k] for k in ("EI", "rho_A", "zeta")}
    j = json.load(open(os.path.join(out, name, "identify.json")))
    check(j["converged"] is True, "%s: converged" % name)
    for p in j["parameters"]:
        t, e, iv = truth[p["name"]], p["estimate"], p["interval"]
        tol = 0.10 if p["name"] == "zeta" else 0.01
        check(abs(e / t - 1) < tol, "%s: %s %.6g against the bench's %.6g (%+.3f %%, within %g %%)" % (name, p["name"], e, t, 100 * (e / t - 1), 100 * tol))
        check(iv is not None and iv["low"] <= t <= iv["high"],
              "%s: %s interval %s covers %.6g" % (name, p["name"], "[%.6g, %.6g]" % (iv["low"], iv["high"]) if iv else "(none)", t))
    modes_dir = os.path.join(out, name + "-modes")
    subprocess.run([os.path.join(build, "crosscheck", "scole-crosscheck"), "modes", "-s", os.path.join(here, "bench-%s.yaml" % name),
                    "--out", modes_dir, "--count", "3", "--levels", "1"], check=True, stdout=subprocess.DEVNULL)
    chain = json.load(open(os.path.join(modes_dir, "modes.json")))
    for k in range(3):
        m, c = j["modes"][k], chain["modes"][k]
        fc, zc = c["chain_hz"][0], c["chain_damping_ratio"]
        what = "%s: mode %d %.5g Hz +- %.3g holds the chain's %.5g Hz" % (name, k + 1, m["frequency_hz"], m["frequency_interval_hz"], fc)
        check(abs(m["frequency_hz"] - fc) <= m["frequency_interval_hz"], what)
        check(abs(m["damping_ratio"] - zc) <= m["damping_ratio_interval"],
              "%s: mode %d damping %.5g +- %.3g holds the chain's %.5g" % (name, k + 1, m["damping_ratio"], m["damping_ratio_interval"], zc))
# One record, four formats: the same estimates (the writers and readers keep every bit).
lvm = {p["name"]: p["estimate"] for p in json.load(open(os.path.join(out, "steel", "identify.json")))["parameters"]}
for ext in ("tdms", "csv", "uff"):
    other = {p["name"]: p["estimate"] for p in json.load(open(os.path.join(out, "steel-as-" + ext, "identify.json")))["parameters"]}
    worst = max(abs(other[k] / lvm[k] - 1) for k in lvm)
    check(worst <= 1e-9, "steel as .%s: estimates within %.1e of the .lvm's (1e-9 asked)" % (ext, worst))
sys.exit(1 if failed else 0)
