"""The scoleid Python module against the programs: the same numbers, the plant it exports, its errors.

Run by ctest (label python) with PYTHONPATH=<build>/python and SCOLEID_BUILD_DIR=<build>.
"""
import json
import os
import subprocess
import time

import numpy as np
import pytest

import scoleid

BUILD = os.environ.get("SCOLEID_BUILD_DIR", "build")
TRUTH = os.path.join(BUILD, "model", "scole-truth")
IDENTIFY = os.path.join(BUILD, "identify", "scole-identify")


def run(*args):
    return subprocess.run(list(args), capture_output=True, text=True, check=False)


def read_csv(path):
    with open(path) as f:
        names = f.readline().strip().split(",")
    values = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return {n: values[:, j] for j, n in enumerate(names)}


def cli_truth_and_identify(tmp_path, name):
    truth_dir, out = tmp_path / "truth", tmp_path / "identify"
    r = run(TRUTH, "-s", name, "-o", str(truth_dir), "-q")
    assert r.returncode == 0, r.stderr
    r = run(IDENTIFY, "-s", name, "--data", str(truth_dir / "truth.csv"), "-o", str(out), "-q")
    assert r.returncode in (0, 1), r.stderr
    with open(out / "identify.json") as f:
        return read_csv(truth_dir / "truth.csv"), json.load(f)


@pytest.mark.parametrize("name,tol", [("paper-beam-1", 1e-12), ("paper-scole-1", 1e-9)])
def test_truth_and_identify_give_the_programs_numbers(tmp_path, request, name, tol):
    csv, cli = cli_truth_and_identify(tmp_path, name)
    rec = request.getfixturevalue("beam_record") if name == "paper-beam-1" else scoleid.truth(name)
    assert list(rec) == list(csv)
    for k in csv:
        scale = max(np.abs(csv[k]).max(), 1e-300)
        assert np.abs(rec[k] - csv[k]).max() <= 1e-12 * scale, k
    idn = scoleid.identify(name, data=rec)
    for p in cli["parameters"]:
        est = idn.estimates[p["name"]]
        print("%s %s: CLI %.17g, Python %.17g" % (name, p["name"], p["estimate"], est))
        assert est == pytest.approx(p["estimate"], rel=tol, abs=0)
    assert idn.converged == cli["converged"]
    assert idn.to_dict()["iterations"] == cli["iterations"]
    assert json.loads(idn.to_json()) == idn.to_dict()
    assert "parameter" in idn.report()


def test_state_space_modes_are_the_fe_modes_and_its_step_response_follows_the_truth(beam_record):
    sc = "paper-beam-1"
    idn = scoleid.identify(sc)  # synthetic data: the estimate is the truth to ~1e-5
    ss, mm = idn.state_space(), idn.modal_model()
    A, B, C, D = ss.A, ss.B, ss.C, ss.D
    assert ss.inputs == ["P"] and ss.outputs == ["w_mid"]
    # The eigenvalues of A are ±iω of the modal model (no damping in this scenario).
    lam = np.linalg.eigvals(A)
    w_ss = np.sort(np.abs(lam.imag))[::2]
    assert np.allclose(w_ss, mm["omega"], rtol=1e-8)
    # ... and the cross-check's FE modes at the truth (same mesh), scaled by sqrt((EI/rho_A) ratio):
    # a uniform beam's frequencies scale exactly with it.
    modes = scoleid.crosscheck_modes(sc, count=10, levels=1)
    fe = np.array([m["fe_hz"][0] for m in modes["modes"]])
    phys = idn.physical
    scale = np.sqrt((phys["EI"] / phys["rho_A"]) / (23000.0 / 67.0))
    f_ss = w_ss[:10] / (2 * np.pi)
    print("state-space vs FE modes (first ten), relative:", f_ss / (fe * scale) - 1)
    assert np.allclose(f_ss, fe * scale, rtol=1e-9)
    # The plant's step response (P = 10 N at t = 0) against the Simbody truth at the true values.
    rec = beam_record
    t = rec["t"]
    vals, vecs = np.linalg.eig(A)
    Vinv_B = np.linalg.solve(vecs, B[:, 0] * 10.0)
    x = np.real(vecs @ (((np.exp(np.outer(vals, t)) - 1.0) / vals[:, None]) * Vinv_B[:, None]))
    y = C @ x + D @ (10.0 * np.ones((1, t.size)))
    rel = np.sqrt(np.mean((y[0] - rec["w_mid"]) ** 2)) / np.sqrt(np.mean(rec["w_mid"] ** 2))
    print("step response of the exported plant vs the Simbody truth: relative RMS %.3g" % rel)
    assert rel < 0.02


def test_modes_and_correlation_follow_the_modal_model_and_the_std():
    # Paper Case I with 2 % noise: the modes are the modal model's (lowest first, in Hz), and the
    # first frequency's std is the paper form's closed form: f ∝ √q1, so std(f)/f = std(q1)/(2 q1).
    sc = scoleid.builtin_scenario("paper-beam-1").replace("location: 5, unit: m}", "location: 5, unit: m, noise_std: 0.00036}")
    assert "noise_std" in sc
    idn = scoleid.identify(sc)
    assert idn.converged
    modes, mm = idn.modes, idn.modal_model()
    assert len(modes) == 10 and list(modes.index) == list(range(1, 11))
    assert not mm["rigid"].any()  # a clamped beam has no rigid-body mode
    assert np.allclose(modes["frequency_hz"], np.asarray(mm["omega"][:10]) / (2 * np.pi), rtol=1e-12)
    # The interval columns are (low, high) about the frequency, as the parameters' are.
    assert (modes["frequency_low_hz"] < modes["frequency_hz"]).all() and (modes["frequency_hz"] < modes["frequency_high_hz"]).all()
    assert np.allclose(modes["frequency_high_hz"] - modes["frequency_hz"], modes["frequency_hz"] - modes["frequency_low_hz"], rtol=1e-9)
    q1, s1 = idn.estimates["q1"], idn.std["q1"]
    f1 = modes.loc[1]
    print("f1 %.7f Hz, std %.3e (closed form %.3e)" % (f1["frequency_hz"], f1["frequency_std_hz"], f1["frequency_hz"] * s1 / (2 * q1)))
    assert f1["frequency_std_hz"] == pytest.approx(f1["frequency_hz"] * s1 / (2 * q1), rel=1e-5)
    # The record's own modes (docs/theory.md §8.4), as identify.json gives them: within 3 of their
    # std of the model's, or a model-form term that makes the interval hold them.
    rec = modes[np.isfinite(modes["record_frequency_hz"])]
    assert 1 in rec.index
    miss = (rec["record_frequency_hz"] - rec["frequency_hz"]).abs()
    flagged = rec["frequency_model_form_hz"] > 0
    assert (miss[~flagged] <= 3 * rec["record_frequency_std_hz"][~flagged]).all()
    assert (miss[flagged] < (rec["frequency_high_hz"] - rec["frequency_hz"])[flagged]).all()
    for k, m in idn._dict["modes"][0]["record"].items():
        assert rec.loc[1, k if k.endswith("model_form") or k.endswith("form_hz") else "record_" + k] == m
    r = idn.correlation
    assert set(r) == {"q1", "q2"}
    assert r["q1"]["q1"] == pytest.approx(1.0) and r["q1"]["q2"] == pytest.approx(r["q2"]["q1"])
    assert -1.0 <= r["q1"]["q2"] <= 1.0


def test_data_as_a_dataframe_and_as_a_file_identify_alike(tmp_path, beam_record):
    pd = pytest.importorskip("pandas")
    rec = beam_record
    from_dict = scoleid.identify("paper-beam-1", data=rec)
    df = pd.DataFrame({k: v for k, v in rec.items()})
    df.attrs["meta"] = rec.meta
    from_df = scoleid.identify("paper-beam-1", data=df)
    assert from_df.estimates == from_dict.estimates
    # A column that happens to be called "meta" is a column like any other.
    odd = df.rename(columns={"P": "meta"})
    odd.attrs["meta"] = rec.meta
    with pytest.raises(scoleid.InputError, match="does not describe column 'meta'"):
        scoleid.identify("paper-beam-1", data=odd)
    # The scenario as YAML text and as a dict give what the name gives.
    text = scoleid.builtin_scenario("paper-beam-1")
    assert scoleid.identify(text).estimates == scoleid.identify("paper-beam-1").estimates
    model = from_dict.export_model(tmp_path / "plant.json")
    with open(tmp_path / "plant.json") as f:
        assert json.load(f) == model
    assert np.allclose(np.array(model["state_space"]["A"]), from_dict.state_space().A, rtol=0, atol=0)
    # The .mat file, read back by scipy.io.loadmat: the same matrices, the names as cells.
    scipy_io = pytest.importorskip("scipy.io")
    from_dict.export_model(tmp_path / "plant.mat")
    mat = scipy_io.loadmat(tmp_path / "plant.mat")
    ss = from_dict.state_space()
    for k in ("A", "B", "C", "D"):
        assert np.array_equal(mat[k], getattr(ss, k)), k
    assert [str(x[0][0]) for x in mat["outputs"]] == ss.outputs
    assert np.array_equal(mat["omega"].ravel(), from_dict.modal_model()["omega"])


def test_errors_are_input_errors_with_the_programs_line():
    with pytest.raises(scoleid.InputError, match="no-such-scenario"):
        scoleid.identify("no-such-scenario")
    with pytest.raises(scoleid.InputError, match=r"beam.EI must be > 0"):
        scoleid.identify({"name": "x", "structure": "beam", "beam": {"EI": -1}})
    # A table without "t" takes its first column as time, as a CSV does: here nothing is left beside it.
    with pytest.raises(scoleid.InputError, match="no data columns beside the time column 'w_mid'"):
        scoleid.identify("paper-beam-1", data={"w_mid": np.zeros(3)})
    with pytest.raises(scoleid.InputError, match="method must be one of"):
        scoleid.identify("paper-beam-1", method="newton")
    assert isinstance(scoleid.InputError("x"), ValueError)


def test_python_overhead_over_the_library_is_small(tmp_path):
    """scoleid.identify against the library call inside it (scenario to verdict) on paper-scole-2."""
    best = None
    for _ in range(2):
        t0 = time.perf_counter()
        idn = scoleid.identify("paper-scole-2")
        wall = time.perf_counter() - t0
        lib = idn.library_seconds
        ratio = wall / lib - 1.0
        best = ratio if best is None else min(best, ratio)
        print("paper-scole-2: Python call %.3f s, library %.3f s, overhead %.2f %%" % (wall, lib, 100 * ratio))
    assert best <= 0.05


def test_ctrl_c_ends_a_solve_under_way():
    """SIGINT during scoleid.identify: the solve stops within a sample and Python sees KeyboardInterrupt."""
    import signal
    import sys
    code = ("import scoleid, sys\n"
            "print('start', flush=True)\n"
            "try:\n"
            "    for _ in range(100):  # solves back to back: the signal finds one under way\n"
            "        scoleid.identify('paper-scole-2')\n"
            "    print('finished')\n"
            "except KeyboardInterrupt as e:\n"
            "    print('KeyboardInterrupt:', e)\n")
    env = dict(os.environ)
    p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    assert p.stdout.readline().strip() == "start"
    time.sleep(1.5)  # inside a solve (paper-scole-2 takes about a second; the child runs them back to back)
    t0 = time.perf_counter()
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=60)
    waited = time.perf_counter() - t0
    print("SIGINT answered in %.3f s: %s" % (waited, out.strip()))
    assert "KeyboardInterrupt: interrupted by SIGINT" in out, out + err
    assert waited < 2.0
    # ... and the handler is Python's again after the call: a second call runs to its end.
    rec = scoleid.identify("paper-beam-1")
    assert rec.converged


def test_crosscheck_trajectories_returns_the_records_side_by_side(tmp_path):
    r = scoleid.crosscheck_trajectories("paper-beam-1", tmp_path / "truths", segments=10, levels=2)
    assert r["t"].ndim == 1 and r["chain"].shape == r["fe"].shape == (r["t"].size, 1)
    rms = r["sensors"][0]["relative_rms"]
    print("paper-beam-1 chain vs FE, relative RMS per level:", rms)
    # The chain's lumping error falls with n (second order): the finer level is closer.
    assert len(rms) == 2 and rms[1] < rms[0] < 0.05
    assert 1.8 < np.log2(rms[0] / rms[1]) < 2.2
    rel = np.sqrt(np.mean((r["chain"] - r["fe"]) ** 2) / np.mean(r["chain"] ** 2))
    assert rel == pytest.approx(rms[1], rel=1e-6)


def test_a_frame_is_identified_storey_by_storey():
    # A four-storey frame (structure: frame, docs/theory.md §2.6) on the identifier's own
    # synthetic record with stated noise: each storey's EI by name, the modes of the fitted model.
    sc = """name: frame-py
structure: frame
units: SI
frame: {heights: [0.3, 0.3, 0.3, 0.3], columns: 2, rho_A: 0.3925, EI: 3.333, floor_mass: [1, 1, 1, 0.8], tau: 2.0e-4}
inputs:
  - {name: hammer, at: frame, kind: force, location: 1.2, unit: N, signal: {type: haversine, amplitude: 20, t0: 0.01, width: 0.01}}
sensors:
  - {name: acc4, at: frame, kind: acceleration, location: 1.2, unit: m/s^2, noise_std: 0.002}
  - {name: acc2, at: frame, kind: acceleration, location: 0.6, unit: m/s^2, noise_std: 0.002}
simulation: {duration: 2, sample_interval: 0.002, seed: 3}
identification: {estimate: [EI_1, EI_2, EI_3, EI_4], elements: 16}
truth: {overrides: {frame: {EI: [3.6, 3.1, 3.45, 3.2]}}}
"""
    idn = scoleid.identify(sc)
    assert idn.converged
    truth = {"EI_1": 3.6, "EI_2": 3.1, "EI_3": 3.45, "EI_4": 3.2}
    for name, t in truth.items():
        err = idn.estimates[name] - t
        print("%s %.5f (truth %.2f), std %.2e" % (name, idn.estimates[name], t, idn.std[name]))
        assert abs(err) < 4 * idn.std[name] + 1e-9
        assert abs(err / t) < 2e-3
    f = idn.modes["frequency_hz"]
    assert 2.8 < f.loc[1] < 3.0 and f.loc[1] < f.loc[2] < f.loc[3] < f.loc[4]
