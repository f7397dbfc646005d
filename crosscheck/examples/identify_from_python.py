"""Identify a beam from a pandas DataFrame, the way a lab's Python script would (typed: mypy --strict).

    PYTHONPATH=build/python python3 crosscheck/examples/identify_from_python.py

A Simbody truth of paper-beam-1 (a pinned beam under a step load, deflection at mid-span) stands in
for a measured record: as a DataFrame indexed by time, with the time in milliseconds as a lab's DAQ
writes it. The identifier returns the estimates as a table, the fit as a DataFrame and the plant as
a scipy.signal.StateSpace.
"""
import warnings

import numpy as np

import scoleid


def main() -> int:
    print("scoleid", scoleid.__version__)
    rec = scoleid.truth("paper-beam-1")
    df = rec.to_dataframe()
    df.index = df.index * 1e3
    df.index.name = "t [ms]"  # the bracketed unit is converted, as in a CSV header
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", scoleid.ScoleidWarning)
        idn = scoleid.identify("paper-beam-1", data=df)
    for w in caught:
        print("warning:", w.message)
    fit = idn.fit
    rel = float(np.sqrt((fit["w_mid_residual"] ** 2).mean() / (fit["w_mid_measured"] ** 2).mean()))
    print("relative RMS residual at w_mid: %.3g" % rel)
    print(idn.modes[["frequency_hz", "frequency_low_hz", "frequency_high_hz"]].head(3).to_string())
    plant = idn.state_space()
    sys = plant.to_scipy()
    print("plant: %d states, inputs %s, outputs %s, %s" % (plant.A.shape[0], plant.inputs, plant.outputs,
                                                         type(sys).__name__))
    summary = idn.summary()  # truth and relative_error too: the truth.json travels in df.attrs["meta"]
    print(summary.to_string())
    errors = {str(name): float(e) for name, e in summary["relative_error"].items()}
    print("relative errors against the truth:", {k: "%.2g" % v for k, v in errors.items()})
    return 0 if idn.converged and errors and all(abs(e) < 1e-2 for e in errors.values()) and rel < 0.05 else 1


if __name__ == "__main__":
    raise SystemExit(main())
