"""The Python API as Python users expect it: pandas in and out, pickling, warnings, progress, help.

Run by ctest (label python) with PYTHONPATH=<build>/python and SCOLEID_BUILD_DIR=<build>.
"""
import contextlib
import inspect
import io
import json
import logging
import os
import pickle
import re
import subprocess
import sys
import warnings

import numpy as np
import pandas as pd
import pytest

import scoleid

BUILD = os.environ.get("SCOLEID_BUILD_DIR", "build")
IDENTIFY = os.path.join(BUILD, "identify", "scole-identify")
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def test_version_is_the_projects():
    with open(os.path.join(ROOT, "CMakeLists.txt")) as f:
        version = re.search(r"project\(scoleid VERSION ([0-9.]+)", f.read()).group(1)
    assert scoleid.__version__ == version


def test_time_in_the_index_in_a_ms_column_in_a_csv_and_through_the_cli_identify_alike(tmp_path, beam_record):
    rec = beam_record
    # A DAQ's CSV: time in milliseconds, stated in the header.
    csv = tmp_path / "daq.csv"
    with open(csv, "w") as f:
        f.write("Time [ms],P,w_mid\n")
        for k in range(rec["t"].size):
            f.write("%.17g,%.17g,%.17g\n" % (rec["t"][k] * 1e3, rec["P"][k], rec["w_mid"][k]))
    r = subprocess.run([IDENTIFY, "-s", "paper-beam-1", "--data", str(csv), "-o", str(tmp_path / "cli"), "-q"],
                       capture_output=True, text=True)
    assert r.returncode in (0, 1), r.stderr
    with open(tmp_path / "cli" / "identify.json") as f:
        cli = {p["name"]: p["estimate"] for p in json.load(f)["parameters"]}
    df = pd.read_csv(csv, float_precision="round_trip")   # the [ms] column first, a RangeIndex
    from_file = scoleid.identify("paper-beam-1", data=str(csv))
    from_columns = scoleid.identify("paper-beam-1", data=df)
    from_index = scoleid.identify("paper-beam-1", data=df.set_index("Time [ms]"))
    from_time_arg = scoleid.identify("paper-beam-1", data=df[["P", "w_mid", "Time [ms]"]], time="Time [ms]")
    print("CLI", cli, "\nPython (file, columns, index, time=)", from_file.estimates, from_columns.estimates,
          from_index.estimates, from_time_arg.estimates)
    for idn in (from_file, from_columns, from_index, from_time_arg):
        assert idn.estimates == cli
    # The [ms] column converted: the same fit as the record's own seconds (to the rounding of t * 1e3 / 1e3).
    seconds = scoleid.identify("paper-beam-1", data=pd.DataFrame({"P": rec["P"], "w_mid": rec["w_mid"]},
                                                                  index=pd.Index(rec["t"], name="t")))
    for k, v in seconds.estimates.items():
        assert cli[k] == pytest.approx(v, rel=1e-9)
    # Time spans (a Timedelta index) are seconds; an unnamed integer index is row numbers, not time.
    spans = pd.DataFrame({"P": rec["P"], "w_mid": rec["w_mid"]}, index=pd.to_timedelta(rec["t"], unit="s"))
    for k, v in scoleid.identify("paper-beam-1", data=spans).estimates.items():
        assert seconds.estimates[k] == pytest.approx(v, rel=1e-6)
    rows = pd.DataFrame({"t": rec["t"], "P": rec["P"], "w_mid": rec["w_mid"]})
    assert scoleid.identify("paper-beam-1", data=rows).estimates == seconds.estimates
    # Units of other columns are applied as a CSV header's: the deflection in mm; the sensor w_mid
    # reads the column 'w_mid [mm]' (a name with its unit), as from a file.
    mm = pd.DataFrame({"P": rec["P"], "w_mid [mm]": rec["w_mid"] * 1e3}, index=pd.Index(rec["t"], name="t"))
    for k, v in scoleid.identify("paper-beam-1", data=mm).estimates.items():
        assert seconds.estimates[k] == pytest.approx(v, rel=1e-9)


def test_time_problems_are_named():
    t = np.arange(40) * 0.01
    d = pd.DataFrame({"P": np.zeros(40), "w_mid": np.zeros(40)}, index=pd.date_range("2026-01-01", periods=40, freq="10ms"))
    with pytest.raises(scoleid.InputError, match=r"the time 't' holds dates .*df.index - df.index\[0\]"):
        scoleid.identify("paper-beam-1", data=d)
    with pytest.raises(scoleid.InputError, match=r"time='tt' is not a column \(P, w_mid\)"):
        scoleid.identify("paper-beam-1", data={"P": t, "w_mid": t}, time="tt")
    spans = pd.DataFrame({"P": t, "w_mid": t}, index=pd.Index(pd.to_timedelta(t, unit="s"), name="time [ms]"))
    with pytest.raises(scoleid.InputError, match=r"holds time spans, which are seconds, not \[ms\]"):
        scoleid.identify("paper-beam-1", data=spans)
    with pytest.raises(scoleid.InputError, match=r"data .data \(dict\).: time column .Time \[m\].: unit .m. is not a unit of time"):
        scoleid.identify("paper-beam-1", data={"Time [m]": t, "P": t, "w_mid": t})
    with pytest.raises(TypeError, match="time= applies to a table"):
        scoleid.identify("paper-beam-1", data="x.csv", time="t")


def test_fit_reproduces_fit_csv_summary_identify_json_and_a_pickle_keeps_every_number(tmp_path):
    sc = scoleid.builtin_scenario("paper-beam-1").replace("location: 5, unit: m}", "location: 5, unit: m, noise_std: 0.00036}")
    idn = scoleid.identify(sc)
    idn.write(tmp_path / "run")
    fit_csv = pd.read_csv(tmp_path / "run" / "fit.csv", index_col=0, float_precision="round_trip")
    fit = idn.fit
    assert list(fit.columns) == list(fit_csv.columns) == ["w_mid_measured", "w_mid_predicted", "w_mid_residual"]
    assert fit.index.name == "t"
    assert np.array_equal(fit.index.to_numpy(), fit_csv.index.to_numpy())
    assert np.array_equal(fit.to_numpy(), fit_csv.to_numpy())
    with open(tmp_path / "run" / "identify.json") as f:
        written = json.load(f)
    s = idn.summary()
    assert list(s.index) == [p["name"] for p in written["parameters"]] == idn.names
    for p in written["parameters"]:
        row = s.loc[p["name"]]
        assert row["estimate"] == p["estimate"] and row["std"] == p["std"] and row["initial"] == p["initial"]
        assert (row["low"], row["high"]) == (p["interval"]["low"], p["interval"]["high"])
        assert row["identifiable"] == p["identifiable"]
        assert row["truth"] == p["truth"] and row["relative_error"] == p["relative_error"]
    assert json.loads(idn.to_json()) == idn.to_dict() == written
    # A pickle round trip (what ProcessPoolExecutor and joblib do) keeps every number.
    back = pickle.loads(pickle.dumps(idn))
    assert back.estimates == idn.estimates and back.std == idn.std and back.intervals == idn.intervals
    assert (back.converged, back.verdict, back.warnings, back.report()) == (idn.converged, idn.verdict, idn.warnings, idn.report())
    assert back.to_json() == idn.to_json()
    pd.testing.assert_frame_equal(back.summary(), s)
    pd.testing.assert_frame_equal(back.fit, fit)
    pd.testing.assert_frame_equal(back.modes, idn.modes)
    a, b = idn.state_space(), back.state_space()
    for k in "ABCD":
        assert np.array_equal(getattr(a, k), getattr(b, k))
    assert (a.inputs, a.outputs, a.output_units) == (b.inputs, b.outputs, b.output_units) == (["P"], ["w_mid"], ["m"])
    assert np.array_equal(idn.modal_model()["omega"], back.modal_model()["omega"])
    with pytest.raises(RuntimeError, match="write\\(\\) needs the solver's state"):
        back.write(tmp_path / "again")
    # The plant as scipy's: its poles are the modal model's.
    sp = a.to_scipy()
    assert np.array_equal(sp.A, a.A) and np.array_equal(sp.D, a.D)
    assert np.allclose(np.sort(np.abs(np.linalg.eigvals(sp.A).imag))[::2], idn.modal_model()["omega"], rtol=1e-9)


def test_a_run_whose_data_determine_nothing_warns():
    t = np.arange(3) * 0.01
    with pytest.warns(scoleid.ScoleidWarning, match="none of the 2") as rec:
        idn = scoleid.identify("paper-beam-1", data={"t": t, "P": np.full(3, 10.0), "w_mid": np.array([0.0, 1e-6, 3e-6])})
    assert not idn.converged
    assert any("not converged" in str(w.message) for w in rec)
    # ... and a converged run with identifiable parameters warns of nothing.
    with warnings.catch_warnings(record=True) as clean:
        warnings.simplefilter("always")
        scoleid.identify("paper-beam-1")
    assert not [w for w in clean if issubclass(w.category, scoleid.ScoleidWarning)]


def test_progress_reaches_a_callback_sys_stdout_and_logging(caplog):
    lines = []
    scoleid.identify("paper-beam-1", progress=lines.append)
    assert lines and lines[0].split()[0] == "iter" and any(l.startswith("fit test:") for l in lines)
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        scoleid.identify("paper-beam-1", verbose=True)
    assert out.getvalue().splitlines() == lines
    with caplog.at_level(logging.INFO, logger="scoleid"):
        scoleid.identify("paper-beam-1")
    assert [r.getMessage() for r in caplog.records if r.name == "scoleid"] == lines

    def stop(line):
        raise RuntimeError("enough: " + line)
    with pytest.raises(RuntimeError, match="enough: +iter"):
        scoleid.identify("paper-beam-1", progress=stop)
    assert scoleid.identify("paper-beam-1").converged  # nothing left behind


def test_every_public_name_is_documented_with_its_parameters():
    public = [n for n in dir(scoleid) if not n.startswith("_")]
    assert sorted(public) == sorted(set(scoleid.__all__) - {"__version__"}), "private imports leak into the namespace"
    checked = 0
    for name in scoleid.__all__:
        obj = getattr(scoleid, name)
        members = [obj]
        if inspect.isclass(obj):
            members += [m for k, m in vars(obj).items() if not k.startswith("_") and (inspect.isfunction(m) or isinstance(m, property))]
        for m in members:
            doc = inspect.getdoc(m.fget if isinstance(m, property) else m)
            assert doc and len(doc) > 20, "%s.%s has no help" % (name, getattr(m, "__name__", m))
            if inspect.isfunction(m):
                for p in inspect.signature(m).parameters:
                    if p != "self":
                        assert re.search(r"\b%s\b" % p, doc), "%s: help does not explain '%s'" % (m.__qualname__, p)
            checked += 1
    print("documented public names and members:", checked)
    assert checked > 30  # the package's functions, classes, methods and properties: none skipped


def test_builtin_scenarios_come_with_the_descriptions_the_cli_prints():
    listed = subprocess.run([IDENTIFY, "--list-scenarios"], capture_output=True, text=True, check=True).stdout.splitlines()
    cli = {l.split()[0]: l.split(None, 1)[1] for l in listed if l.strip()}
    assert scoleid.builtin_scenarios() == cli


def test_rigid_modes_are_flagged():
    free = scoleid.builtin_scenario("paper-beam-1")
    sc = {"name": "free-free", "structure": "beam", "units": "SI",
          "beam": {"length": 1.0, "left": "free", "right": "free", "rho_A": 1.0, "EI": 10.0},
          "inputs": [{"name": "F", "kind": "force", "location": 0.0, "unit": "N",
                      "signal": {"type": "haversine", "amplitude": 1.0, "t0": 0.001, "width": 0.002}}],
          "sensors": [{"name": "a", "kind": "acceleration", "location": 1.0, "unit": "m/s^2"}],
          "simulation": {"duration": 0.05, "sample_interval": 0.0005},
          "identification": {"estimate": ["EI"], "initial": {"EI": 9.0}, "elements": 4}}
    assert free  # the built-in exists; the free-free beam is ours
    mm = scoleid.identify(sc, compute_std=False).modal_model()
    print("free-free beam: omega", mm["omega"][:4], "rigid", mm["rigid"][:4])
    assert list(mm["rigid"][:2]) == [True, True] and not mm["rigid"][2:].any()
    assert np.isnan(mm["zeta"][:2]).all()


def test_the_example_passes_mypy_strict_and_runs(tmp_path):
    example = os.path.join(ROOT, "crosscheck", "examples", "identify_from_python.py")
    env = dict(os.environ, MYPYPATH=os.path.join(BUILD, "python"))
    r = subprocess.run([sys.executable, "-m", "mypy", "--strict", "--cache-dir", str(tmp_path / "mypy"), example],
                       capture_output=True, text=True, env=env)
    print(r.stdout)
    assert r.returncode == 0, r.stdout + r.stderr
    r = subprocess.run([sys.executable, example], capture_output=True, text=True)
    print(r.stdout)
    assert r.returncode == 0, r.stdout + r.stderr


def test_a_call_from_a_progress_callback_is_refused_not_a_deadlock():
    code = ("import scoleid\n"
            "try:\n"
            "    scoleid.identify('paper-beam-1', progress=lambda line: scoleid.truth('paper-beam-1'))\n"
            "except RuntimeError as e:\n"
            "    print('RuntimeError:', e)\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert "RuntimeError: scoleid: a library call cannot be made from within another" in r.stdout, r.stdout + r.stderr


def test_a_process_forked_while_a_thread_is_in_a_call_starts_free():
    code = ("import os, threading, time, scoleid\n"
            "th = threading.Thread(target=lambda: scoleid.identify('paper-scole-2'))\n"
            "th.start(); time.sleep(0.3)\n"
            "pid = os.fork()\n"
            "if pid == 0:\n"
            "    idn = scoleid.identify('paper-beam-1')\n"
            "    os._exit(0 if idn.converged else 3)\n"
            "_, status = os.waitpid(pid, 0)\n"
            "th.join()\n"
            "print('child', os.waitstatus_to_exitcode(status))\n")
    r = subprocess.run([sys.executable, "-W", "ignore", "-c", code], capture_output=True, text=True, timeout=120)
    assert "child 0" in r.stdout, r.stdout + r.stderr


def test_row_numbers_are_not_time_and_unused_text_columns_are_left_out(beam_record):
    rec = beam_record
    plain = scoleid.identify("paper-beam-1", data=rec)
    df = pd.DataFrame({"t": rec["t"], "P": rec["P"], "w_mid": rec["w_mid"]}).rename_axis("sample")
    df["label"] = ["tap"] * len(df)  # a text column no sensor reads
    assert scoleid.identify("paper-beam-1", data=df).estimates == plain.estimates
    df["w_mid"] = df["w_mid"].astype(str).where(df.index > 3, "x")  # a text column a sensor reads: refused
    with pytest.raises(scoleid.InputError, match="column 'w_mid' is not numeric"):
        scoleid.identify("paper-beam-1", data=df)


def test_results_handed_out_are_copies_and_truth_metadata_is_named_when_stale(beam_record):
    idn = scoleid.identify("paper-beam-1")
    a0 = idn.state_space().A[0, 0]
    ss = idn.state_space()
    ss.A[0, 0] = 12345.0
    mm = idn.modal_model()
    mm["omega"][0] = -1.0
    idn.iterations[0]["cost"] = -1.0
    assert idn.state_space().A[0, 0] == a0
    assert idn.modal_model()["omega"][0] > 0 and idn.iterations[0]["cost"] > 0
    df = beam_record.to_dataframe().rename(columns={"w_mid": "w_mid [mm]"})
    df["w_mid [mm]"] *= 1e3
    with pytest.raises(scoleid.InputError, match=r"data.attrs\['meta'\].*does not describe column 'w_mid \[mm\]'"):
        scoleid.identify("paper-beam-1", data=df)
    del df.attrs["meta"]
    for k, v in scoleid.identify("paper-beam-1", data=df).estimates.items():
        assert v == pytest.approx(scoleid.identify("paper-beam-1", data=beam_record).estimates[k], rel=1e-9)


def test_read_data_and_frf_give_what_the_programs_give(tmp_path):
    # A record as a DAQ writes it: units in brackets; acc = 0.5 F (in g per N) plus noise.
    rng = np.random.default_rng(3)
    n, fs = 40000, 2048.0
    force = rng.normal(size=n)
    acc = 0.5 * force + 0.01 * rng.normal(size=n)
    df = pd.DataFrame({"F [N]": force, "acc [g]": acc}, index=pd.Index(np.arange(n) / fs, name="t [s]"))
    path = tmp_path / "r.csv"
    df.to_csv(path)
    back = scoleid.read_data(path)
    assert back.attrs["units"] == {"F [N]": "N", "acc [g]": "g"}
    np.testing.assert_allclose(back["acc [g]"].to_numpy(), acc, rtol=1e-15)
    np.testing.assert_allclose(back.index.to_numpy(), np.arange(n) / fs, rtol=1e-15)

    r = scoleid.frf(path, "F [N]")
    assert r.orders == {"acc [g]": 2}
    # Within the F law's 1e-9 level of the exact 0.5 g/N = 4.903325 (m/s^2)/N (frf_estimate.h).
    K = r.segments
    z = np.abs(r.H["acc [g]"].to_numpy() - 0.5 * 9.80665) ** 2 / r.std["acc [g]"].to_numpy() ** 2
    assert z.max() < (K - 1) * (1e-9 ** (-1.0 / (K - 1)) - 1), (K, z.max())
    assert r.coherence is not None and (r.coherence["acc [g]"] > 0.99).all()
    # The same numbers as scole-data frf writes.
    subprocess.run([os.path.join(BUILD, "io", "scole-data"), "frf", str(path), "--input", "F [N]", "-q", "-o", str(tmp_path / "h.csv")],
                   check=True)
    cli = pd.read_csv(tmp_path / "h.csv", float_precision="round_trip")
    np.testing.assert_array_equal(cli["f_hz"].to_numpy(), r.H.index.to_numpy())
    np.testing.assert_array_equal(cli["acc [g] re"].to_numpy(), r.H["acc [g]"].to_numpy().real)
    np.testing.assert_array_equal(cli["acc [g] std"].to_numpy(), r.std["acc [g]"].to_numpy())

    # The impact estimator, the same record taken as one segment: H at s = decay + iω (a constant
    # H here), the noise stated in the column's unit; the numbers and the decay column as the CLI's.
    imp = scoleid.frf(path, "F [N]", estimator="impact", decay=2.0, noise={"acc [g]": 0.01})
    assert imp.decay == 2.0 and imp.segments == 0 and "impact" in imp.note
    zi = np.abs(imp.H["acc [g]"].to_numpy() - 0.5 * 9.80665) ** 2 / imp.std["acc [g]"].to_numpy() ** 2
    assert zi.max() < 30, zi.max()
    subprocess.run([os.path.join(BUILD, "io", "scole-data"), "frf", str(path), "--input", "F [N]", "--estimator", "impact",
                    "--decay", "2", "--noise", "acc [g]=0.01", "-q", "-o", str(tmp_path / "i.csv")], check=True)
    icli = pd.read_csv(tmp_path / "i.csv", float_precision="round_trip")
    assert (icli["decay_per_s"] == 2.0).all()
    np.testing.assert_array_equal(icli["acc [g] re"].to_numpy(), imp.H["acc [g]"].to_numpy().real)
    with pytest.raises(scoleid.InputError, match="no noise level for the impact estimator"):
        scoleid.frf(path, "F [N]", estimator="impact")  # the force acts from the first sample: no quiet start
    with pytest.raises(TypeError, match="noise must be a dict"):
        scoleid.frf(path, "F [N]", estimator="impact", noise=0.01)

    with pytest.raises(scoleid.InputError, match="names no column of the file"):
        scoleid.frf(path, "nope")
    with pytest.raises(scoleid.InputError, match="estimator must be"):
        scoleid.frf(path, "F [N]", estimator="h3")
    with pytest.raises(TypeError, match="input must be a str"):
        scoleid.frf(path, 3)
    with pytest.raises(TypeError, match="path must be a path"):
        scoleid.read_data(3)
