"""Data handed over from Python pass the checks a data file passes, and nothing crashes.

Every shape and value a pandas or numpy user may hand over (empty frames, NaN, None, inf,
complex, times out of order, 2-D columns, dates, objects) ends either in a result or in
scoleid.InputError naming the column: never another exception, never a crash of the interpreter.
"""
import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import scoleid

SCENARIO = "paper-beam-1"  # inputs P, sensor w_mid


def identify(data):
    return scoleid.identify(SCENARIO, data=data, max_iterations=0, compute_std=False)


def good(n=40):
    t = np.arange(n) * 0.01
    return {"t": t, "P": np.where(t < 0.1, 10.0, 0.0), "w_mid": 1e-4 * np.sin(7 * t)}


@pytest.mark.parametrize("case,message", [
    ("empty", "needs at least 2 samples"),
    ("nan", "column 'w_mid', sample 6 .* must be finite, got nan"),
    ("none", "column 'P', sample 4 .* must be finite"),
    ("inf", "column 'P', sample 3 .* must be finite, got inf"),
    ("swapped", "time, sample 5: must be strictly increasing"),
    ("equal", "time, sample 2: must be strictly increasing"),
    ("complex", "column 'w_mid' is complex"),
    ("column2d", r"column 'w_mid' has shape \(40, 1\)"),
    ("time2d", r"column 't' has shape \(40, 1\)"),
    ("short", "column 'w_mid' has 39 values for 40 times"),
    ("strings", "column 'P' is not numeric"),
    ("dates", "column 'P' holds dates"),
    ("spans", "column 'P' holds time spans; pass time='P'"),
    ("nullable", "column 'w_mid', sample 4 .* must be finite"),
    ("too_many", "more than 5000000"),
])
def test_bad_data_are_input_errors_naming_the_column(case, message):
    d = good()
    if case == "empty":
        d = pd.DataFrame(columns=["t", "P", "w_mid"], dtype=float)
    elif case == "nan":
        d["w_mid"] = d["w_mid"].copy()
        d["w_mid"][5] = np.nan
    elif case == "none":
        p = list(d["P"])
        p[3] = None
        d["P"] = p
    elif case == "inf":
        d["P"] = d["P"].copy()
        d["P"][2] = np.inf
    elif case == "swapped":
        t = d["t"].copy()
        t[[3, 4]] = t[[4, 3]]
        d["t"] = t
    elif case == "equal":
        d["t"] = d["t"].copy()
        d["t"][1] = d["t"][0]
    elif case == "complex":
        d["w_mid"] = d["w_mid"] + 0j
    elif case == "column2d":
        d["w_mid"] = d["w_mid"][:, None]
    elif case == "time2d":
        d["t"] = d["t"][:, None]
    elif case == "short":
        d["w_mid"] = d["w_mid"][:-1]
    elif case == "strings":
        d["P"] = ["x"] * 40
    elif case == "dates":
        d["P"] = pd.date_range("2026-01-01", periods=40, freq="s")
    elif case == "spans":
        d["P"] = pd.timedelta_range(0, periods=40, freq="s")
    elif case == "nullable":
        df = pd.DataFrame(d)
        df["w_mid"] = df["w_mid"].astype("Float64")
        df.loc[3, "w_mid"] = pd.NA
        d = df
    elif case == "too_many":
        n = 5_000_001
        d = {"t": np.arange(n) * 1e-5, "P": np.zeros(n), "w_mid": np.zeros(n)}
    with pytest.raises(scoleid.InputError, match=message):
        identify(d)


def test_arguments_of_the_wrong_type_are_type_errors_that_say_what_is_expected():
    with pytest.raises(TypeError, match="data: None, a file path, a dict of arrays or a pandas DataFrame, got int"):
        identify(123)
    with pytest.raises(TypeError, match="max_iterations must be an integer, got float 2.0"):
        scoleid.identify(SCENARIO, data=good(), max_iterations=2.0)
    with pytest.raises(TypeError, match="compute_std must be True or False"):
        scoleid.identify(SCENARIO, data=good(), compute_std="no")
    with pytest.raises(TypeError, match="progress must be a callable"):
        scoleid.identify(SCENARIO, data=good(), progress="log.txt")
    # numpy integers are integers
    assert scoleid.identify(SCENARIO, data=good(), max_iterations=np.int64(0), compute_std=False).iterations is not None


def test_good_data_as_a_dict_and_as_a_dataframe_identify_alike():
    a = identify(good())
    b = identify(pd.DataFrame(good()))
    assert a.estimates == b.estimates


_values = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True, width=64),
    st.just(None),
    st.complex_numbers(max_magnitude=1.0),
    st.integers(min_value=-10, max_value=10),
)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(n=st.integers(min_value=0, max_value=30), bad=st.lists(st.tuples(st.sampled_from(["t", "P", "w_mid"]),
                                                                        st.integers(min_value=0, max_value=29), _values),
                                                              max_size=3),
       shape=st.sampled_from(["flat", "column", "row"]), frame=st.booleans())
def test_any_data_end_in_a_result_or_an_input_error(n, bad, shape, frame):
    d = {k: list(v) for k, v in good(n).items()}
    for col, i, v in bad:
        if i < n:
            d[col][i] = v
    arrays = {}
    for k, v in d.items():
        a = np.array(v, dtype=object if any(x is None or isinstance(x, complex) for x in v) else float)
        if shape == "column" and k == "w_mid":
            a = a.reshape(-1, 1)
        elif shape == "row" and k == "P":
            a = a.reshape(1, -1)
        arrays[k] = a
    data = arrays
    if frame and shape == "flat":
        data = pd.DataFrame({k: list(v) for k, v in arrays.items()})
    try:
        r = identify(data)
    except scoleid.InputError:
        return
    # A result only for data a file could hold: finite, increasing times, at least 2 samples.
    t = np.asarray(arrays["t"], dtype=float)
    assert t.size >= 2 and np.all(np.diff(t) > 0)
    for k in ("P", "w_mid"):
        assert np.all(np.isfinite(np.asarray(arrays[k], dtype=complex).real))
    assert r is not None


def test_an_unknown_builtin_names_no_command_line_option():
    with pytest.raises(scoleid.InputError, match=r"^'nope' is not a built-in scenario \(paper-beam-1"):
        scoleid.builtin_scenario("nope")


def test_numpy_scalars_in_a_scenario_dict_are_numbers_and_other_objects_input_errors():
    base = {"name": "x", "structure": "beam",
            "beam": {"length": 10, "left": "pinned", "right": "pinned", "rho_A": 67, "EI": 23000},
            "inputs": [{"name": "P", "location": 5, "signal": {"type": "step", "amplitude": 10}}],
            "sensors": [{"name": "w_mid", "location": 5}],
            "simulation": {"duration": 1, "sample_interval": 0.01},
            "identification": {"estimate": ["EI"], "initial": {"EI": 20000}, "elements": 10, "max_iterations": 0}}
    plain = scoleid.identify(base, compute_std=False)
    typed = dict(base, identification=dict(base["identification"], elements=np.int64(10), max_iterations=np.int32(0)),
                 beam=dict(base["beam"], EI=np.float32(23000.0)))
    assert scoleid.identify(typed, compute_std=False).estimates == plain.estimates
    with pytest.raises(scoleid.InputError, match="a value of type object"):
        scoleid.identify(dict(base, description=object()))


def test_export_model_and_write_never_overwrite_the_data(tmp_path):
    import pandas as pd
    data = tmp_path / "d.json"  # a CSV under a .json name: read as data, and no place for the model
    pd.DataFrame(good(100)).to_csv(data, index=False)
    before = data.read_bytes()
    r = identify(str(data))
    with pytest.raises(scoleid.InputError, match="is an input of this identification"):
        r.export_model(str(data))
    with pytest.raises(scoleid.InputError, match="NUL character"):
        r.export_model(str(data) + "\0.json")
    with pytest.raises(scoleid.InputError, match="holds an input of this run"):
        r.write(str(tmp_path))
    assert data.read_bytes() == before


def test_a_complex_dataframe_column_is_refused_not_cast():
    import pandas as pd
    d = pd.DataFrame(good())
    d["w_mid"] = d["w_mid"] + 1j
    with pytest.raises(scoleid.InputError, match="column 'w_mid' is complex"):
        identify(d)
    o = pd.DataFrame(good())
    o["w_mid"] = list(o["w_mid"].astype(object))
    o.loc[3, "w_mid"] = 1 + 2j
    with pytest.raises(scoleid.InputError, match="column 'w_mid' is complex"):
        identify(o)
