"""scoleid from Python: identify the distributed parameters of a flexible structure from data.

    import scoleid
    rec = scoleid.truth("paper-beam-1")                  # Simbody truth: {"t": array, column: array, ...}
    idn = scoleid.identify("paper-beam-1", data=rec)     # the FE costate identifier on those arrays
    print(idn.report())                                  # the table scole-identify prints
    plant = idn.state_space()                            # {"A", "B", "C", "D", "inputs", "outputs"}

A scenario is a built-in name, a YAML file's path, YAML text, or a dict with the YAML's structure.
Data are None (the scenario synthesises them), a file (CSV or Universal File), a dict of equal-length
arrays with a "t" entry, or a pandas DataFrame (a "t" column, else its first column is time). A record's truth.json (true values,
noise levels) travels as TruthRecord.meta, or a DataFrame's attrs["meta"].
The numbers are those of the programs (scole-truth, scole-identify, scole-crosscheck); bad input
raises scoleid.InputError (a ValueError) with their one-line message; Ctrl-C ends a solve under way.
"""
import json
import os

import numpy as np

from . import _core

InputError = _core.InputError

__all__ = ["InputError", "builtin_scenarios", "builtin_scenario", "load_scenario", "truth", "identify",
           "Identification", "TruthRecord", "crosscheck_modes", "crosscheck_trajectories"]


def builtin_scenarios():
    """The built-in scenarios' names."""
    return list(_core.builtin_scenarios())


def builtin_scenario(name):
    """A built-in scenario as YAML text (edit it, or pass it on as it is)."""
    return _core.builtin_scenario(name)


def load_scenario(path):
    """A scenario file's YAML text, checked as the programs check it (InputError otherwise)."""
    _core.scenario_json(os.fspath(path), "")
    with open(path, encoding="utf-8") as f:
        return f.read()


def _json_value(x):
    """A scenario dict's numpy scalars, 0-d arrays, Decimal and Fraction as the numbers they hold."""
    import decimal
    import fractions
    if isinstance(x, np.generic) or (isinstance(x, np.ndarray) and x.ndim == 0):
        return x.item()
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, (decimal.Decimal, fractions.Fraction)):
        return float(x)
    raise InputError("scenario (dict): a value of type %s is not a number, text, list or dict: %r" % (type(x).__name__, x))


def _scenario(scenario):
    """(text, source) for _core: source "" means `text` is a built-in name or a file path."""
    if isinstance(scenario, dict):
        return json.dumps(scenario, default=_json_value), "scenario (dict)"
    if isinstance(scenario, os.PathLike):
        return os.fspath(scenario), ""
    if not isinstance(scenario, str):
        raise TypeError("scenario: a built-in name, a path, YAML text or a dict, got %s" % type(scenario).__name__)
    if "\n" in scenario or ":" in scenario and not os.path.exists(scenario):
        return scenario, "scenario (YAML text)"
    return scenario, ""


class TruthRecord(dict):
    """A Simbody truth: {"t": times, column: values, ...}; `meta` is its truth.json (a dict)."""

    def __init__(self, columns, meta):
        super().__init__(columns)
        self.meta = meta


def truth(scenario, progress=False):
    """The Simbody truth of a scenario, as scole-truth computes it (the same numbers)."""
    text, source = _scenario(scenario)
    (names, t, values), meta = _core.truth(text, source, progress)
    cols = {"t": t}
    for j, n in enumerate(names):
        cols[n] = np.ascontiguousarray(values[:, j])
    return TruthRecord(cols, json.loads(meta))


def _column(name, values, n=None):
    """One column as a 1-D float array of n values; InputError for anything else."""
    if getattr(getattr(values, "dtype", None), "kind", "") in ("m", "M"):
        raise InputError("data: column '%s' holds dates or time spans (%s); give seconds as numbers" % (name, values.dtype))
    if getattr(getattr(values, "dtype", None), "kind", "") == "c" or (
            getattr(values, "dtype", None) == object and any(isinstance(x, (complex, np.complexfloating)) for x in values)):
        raise InputError("data: column '%s' is complex; give real values (a time record)" % name)
    if hasattr(values, "to_numpy"):  # a pandas Series (nullable dtypes: NA becomes NaN, refused below)
        try:
            values = values.to_numpy(dtype=float, na_value=np.nan)
        except (TypeError, ValueError) as e:
            raise InputError("data: column '%s' is not numeric (%s)" % (name, e)) from None
    a = np.asarray(values)
    if np.iscomplexobj(a) or (a.dtype == object and any(isinstance(x, (complex, np.complexfloating)) for x in a.ravel())):
        raise InputError("data: column '%s' is complex; give real values (a time record)" % name)
    if a.dtype.kind in "mM":
        raise InputError("data: column '%s' holds dates or time spans (%s); give seconds as numbers" % (name, a.dtype))
    try:
        a = np.asarray(a, dtype=float)
    except (TypeError, ValueError) as e:
        raise InputError("data: column '%s' is not numeric (%s)" % (name, e)) from None
    if a.ndim != 1:
        raise InputError("data: column '%s' has shape %s; give a 1-D array%s"
                         % (name, a.shape, "" if n is None else " of %d values" % n))
    if n is not None and a.size != n:
        raise InputError("data: column '%s' has %d values for %d times" % (name, a.size, n))
    return a


def _table(data):
    """(names, t, values[samples x columns], meta_json) of a dict or DataFrame."""
    if hasattr(data, "columns") and hasattr(data, "to_numpy"):  # a pandas DataFrame (truth.json in .attrs["meta"])
        meta = getattr(data, "attrs", {}).get("meta")
        if len(set(map(str, data.columns))) != len(data.columns):
            raise InputError("data: the DataFrame's column names repeat")
        if len(data.columns) == 0:
            raise InputError("data: the DataFrame has no columns")
        cols = {str(c): data[c] for c in data.columns}
        if "t" not in cols:
            first = str(data.columns[0])
            cols = {"t": cols.pop(first), **cols}
        data = cols
    elif isinstance(data, dict):
        meta = data.meta if isinstance(data, TruthRecord) else None
    else:
        raise InputError("data: a dict of arrays with a \"t\" entry, a pandas DataFrame or a file path, got %s"
                         % type(data).__name__)
    if "t" not in data:
        raise InputError('data: a dict of arrays needs a "t" entry (the sample times)')
    t = _column("t", data["t"])
    names = [str(k) for k in data if k != "t"]
    values = np.empty((t.size, len(names)))
    for j, (k, n) in enumerate(zip([k for k in data if k != "t"], names)):
        values[:, j] = _column(n, data[k], t.size)
    return names, t, values, json.dumps(meta) if meta is not None else ""


class Identification:
    """One identification: estimates with their std and intervals, the verdict it earned, the model."""

    def __init__(self, core, library_seconds=float("nan")):
        self._core = core
        self._json = json.loads(core.to_json())
        #: seconds the library call took (scenario to verdict), without the Python around it
        self.library_seconds = library_seconds

    @property
    def converged(self):
        """True only when the optimiser converged and the model explains the data (the fit test)."""
        return self._core.converged

    @property
    def verdict(self):
        """Why the run is not converged, in one line ("" when it is)."""
        return self._core.verdict

    @property
    def exit_code(self):
        return self._core.exit_code

    @property
    def warnings(self):
        return list(self._core.warnings)

    @property
    def names(self):
        return list(self._core.names)

    @property
    def estimates(self):
        """{parameter: estimate}"""
        return {p["name"]: p["estimate"] for p in self._json["parameters"]}

    @property
    def physical(self):
        """The structure's physical values at the estimate (EI, rho_A, zeta, ...)."""
        return dict(self._json["physical_estimate"])

    @property
    def std(self):
        """{parameter: standard deviation} (None where not assessed or not identifiable)."""
        return {p["name"]: p.get("std") for p in self._json["parameters"]}

    @property
    def intervals(self):
        """{parameter: (low, high)} of the reported uncertainty interval (None where there is none)."""
        out = {}
        for p in self._json["parameters"]:
            i = p.get("interval")
            out[p["name"]] = (i["low"], i["high"]) if isinstance(i, dict) and "low" in i else None
        return out

    @property
    def identifiable(self):
        return {p["name"]: p.get("identifiable") for p in self._json["parameters"]}

    @property
    def modes(self):
        """The identified model's elastic modes, lowest first: dicts with frequency_hz,
        frequency_std_hz, frequency_interval_hz, damping_ratio, damping_ratio_std,
        damping_ratio_interval (None where not assessed; docs/theory.md §8.3)."""
        return [dict(m) for m in self._json.get("modes", [])]

    @property
    def correlation(self):
        """The correlation matrix of the estimates as {parameter: {parameter: r}} (None where a
        parameter has no covariance)."""
        c = self._json.get("identifiability", {}).get("correlation")
        if not c:
            return {}
        names = c["parameters"]
        return {a: {b: c["matrix"][i][j] for j, b in enumerate(names)} for i, a in enumerate(names)}

    @property
    def iterations(self):
        """The iteration history, as identify.json's "iterations"."""
        return list(self._json.get("iterations", []))

    def to_json(self):
        """identify.json, as a dict."""
        return json.loads(self._core.to_json())

    def report(self):
        """The table scole-identify prints."""
        return self._core.report()

    def state_space(self):
        """{"A", "B", "C", "D", "inputs", "outputs"}: the identified linear FE model, x = (u, du/dt),
        in the scenario's units; y = C x + D f."""
        return dict(self._core.state_space())

    def modal_model(self):
        """{"omega" [rad/s], "zeta", "output_shapes" (outputs x modes), "input_shapes", ...}."""
        return dict(self._core.modal_model())

    def export_model(self, path):
        """The state space and the modal model to path.json, or path.mat (MATLAB: A, B, C, D, inputs,
        outputs, omega, zeta, output_shapes, input_shapes), as scole-identify --export-model writes
        them. Returns the model as a dict."""
        self._core.export_model(os.fspath(path))
        return json.loads(self._core.model_json())

    def write(self, directory):
        """identify.json, fit.csv, fit.gp, spectrum.csv, spectrum.gp (and fit.png, spectrum.png with gnuplot) into `directory`."""
        self._core.write(os.fspath(directory))

    def __repr__(self):
        return "<scoleid.Identification %s: %s>" % (
            ", ".join("%s=%.6g" % kv for kv in self.estimates.items()),
            "converged" if self.converged else "not converged (%s)" % self.verdict)


def identify(scenario, data=None, method=None, max_iterations=None, compute_std=True, verbose=False):
    """Identify the scenario's parameters from data, as scole-identify does (the same numbers)."""
    text, source = _scenario(scenario)
    args = _core.IdentifyArgs()
    if data is None:
        pass
    elif isinstance(data, (str, os.PathLike)):
        args.data_file = os.fspath(data)
    else:
        args.names, args.t, args.values, args.meta_json = _table(data)
    args.method = method
    args.max_iterations = max_iterations
    args.compute_std = compute_std
    args.verbose = verbose
    core, seconds = _core.identify(text, source, args)
    return Identification(core, seconds)


def crosscheck_modes(scenario, count=10, segments=0, elements=0, levels=3):
    """The Simbody chain's modes against the FE model's (scole-crosscheck modes), as a dict."""
    text, source = _scenario(scenario)
    return json.loads(_core.crosscheck_modes(text, source, count, segments, elements, levels))


def crosscheck_trajectories(scenario, truth_dir, segments=0, levels=3, elements=0):
    """The chain's and the FE model's sensor records side by side (scole-crosscheck trajectories):
    the report as a dict, with "t", "chain" and "fe" (samples x sensors, finest level) as arrays."""
    text, source = _scenario(scenario)
    report, t, chain, fe = _core.crosscheck_trajectories(text, source, segments, levels, elements, os.fspath(truth_dir))
    out = json.loads(report)
    out.update({"t": t, "chain": chain, "fe": fe})
    return out
