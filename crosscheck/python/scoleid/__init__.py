"""scoleid from Python: identify the distributed parameters of a flexible structure from data.

    import scoleid
    rec = scoleid.truth("paper-beam-1")                  # Simbody truth: {"t": array, column: array, ...}
    idn = scoleid.identify("paper-beam-1", data=rec)     # the FE costate identifier on those arrays
    print(idn.report())                                  # the table scole-identify prints
    idn.summary()                                        # pandas: estimate, std, low, high, identifiable
    idn.fit                                              # pandas: measured, predicted, residual per sensor
    plant = idn.state_space().to_scipy()                 # scipy.signal.StateSpace

Scenarios. A built-in name (``builtin_scenarios()``), a YAML file's path, YAML text, or a dict with
the YAML's structure (numpy scalars and arrays are taken as the numbers they hold).

Data. ``None`` (the scenario synthesises its own), a file (CSV, Universal File, LabVIEW LVM: read as
``scole-identify --data`` reads it), a dict of equal-length arrays, or a pandas DataFrame. The time
of a table is, in this order: the column or array given as ``time=``; a DataFrame's index when it
holds floats, time spans or dates, or integers under a time's name (``t``, ``time``, a bracketed
unit such as ``t [ms]``; an integer index under another name, ``sample``, counts rows); the
scenario's ``data.time_column``; a column named ``t``; the first column. A text column that no
sensor or input reads is left out. Column names are read as a CSV header is: a bracketed suffix states the unit (``"Time [ms]"``, ``"acc_tip [g]"``,
``"hammer [lbf]"``) and is converted exactly as the CSV reader converts it; a time-span
(``Timedelta``) time is taken in seconds. A record's truth.json (true values, noise levels) travels
as ``TruthRecord.meta`` or a DataFrame's ``attrs["meta"]``.

Files. ``read_data(path)`` reads a lab's record (CSV, UFF, LVM, TDMS) into a DataFrame as
``--data`` reads it; ``frf(path, input="F [N]")`` turns a record of any length into frequency
responses as ``scole-data frf`` does (Welch streamed, or harmonic lines), in SI with each value's std.

Results. The numbers are those of the programs (scole-truth, scole-identify, scole-crosscheck), bit
for bit. What the user must know of a run (nothing identifiable, not converged) is also emitted as a
``ScoleidWarning``; progress lines go to ``progress=``, to ``sys.stdout`` with ``verbose=True``, and
to the ``logging`` logger ``"scoleid"`` (level INFO) when it is enabled. An ``Identification``
pickles (its numbers; see ``Identification.write``).

Errors. Bad input raises ``scoleid.InputError`` (a ``ValueError``) with the programs' one-line
message; an argument of the wrong type raises ``TypeError``; Ctrl-C ends a solve under way
(``KeyboardInterrupt``).

Threads. One library call runs at a time in a process: calls from several threads wait for one
another (the solver's signal handling belongs to the process). The GIL is released while a call
runs. For runs in parallel use processes (``concurrent.futures.ProcessPoolExecutor``, joblib; a
process forked while another thread is inside a call starts with the library free).
"""
import json as _json
import logging as _logging
import math as _math
import operator as _operator
import os as _os
import re as _re
import sys as _sys
import warnings as _warnings

import numpy as _np

from . import _core

__version__ = _core.__version__

InputError = _core.InputError
InputError.__doc__ = ("Bad input (a scenario field, a data column, a file): the programs' one-line message, naming the "
                      "file, field and value. A ValueError.")

__all__ = ["__version__", "InputError", "ScoleidWarning", "builtin_scenarios", "builtin_scenario", "load_scenario",
           "truth", "identify", "Identification", "TruthRecord", "StateSpace", "crosscheck_modes",
           "crosscheck_trajectories", "read_data", "frf", "Frf"]

_log = _logging.getLogger("scoleid")


class ScoleidWarning(UserWarning):
    """What the user must know of a result: no parameter identifiable, a run not converged (with why)."""


def builtin_scenarios():
    """The built-in scenarios: ``{name: one-line description}``, in the order ``--list-scenarios`` prints them.

    Returns:
        dict[str, str]
    """
    return {n: _core.builtin_scenario_description(n) for n in _core.builtin_scenarios()}


def builtin_scenario(name):
    """A built-in scenario as YAML text (edit it, or pass it on as it is).

    Args:
        name (str): one of ``builtin_scenarios()``.
    Returns:
        str: the YAML text.
    Raises:
        InputError: no built-in scenario has that name.
    """
    if not isinstance(name, str):
        raise TypeError("builtin_scenario: name must be a str, got %s" % type(name).__name__)
    return _core.builtin_scenario(name)


def load_scenario(path):
    """A scenario file's YAML text, checked as the programs check it.

    Args:
        path (str | os.PathLike): a YAML (or JSON) scenario file.
    Returns:
        str: the file's text.
    Raises:
        InputError: the file is missing or a field is invalid (the message names it).
    """
    _core.scenario_json(_os.fspath(path), "")
    with open(path, encoding="utf-8") as f:
        return f.read()


def _json_value(x):
    """A scenario dict's numpy scalars, 0-d arrays, Decimal and Fraction as the numbers they hold."""
    import decimal
    import fractions
    if isinstance(x, _np.generic) or (isinstance(x, _np.ndarray) and x.ndim == 0):
        return x.item()
    if isinstance(x, _np.ndarray):
        return x.tolist()
    if isinstance(x, (decimal.Decimal, fractions.Fraction)):
        return float(x)
    raise InputError("scenario (dict): a value of type %s is not a number, text, list or dict: %r" % (type(x).__name__, x))


def _scenario(scenario):
    """(text, source) for _core: source "" means `text` is a built-in name or a file path."""
    if isinstance(scenario, dict):
        return _json.dumps(scenario, default=_json_value), "scenario (dict)"
    if isinstance(scenario, _os.PathLike):
        return _os.fspath(scenario), ""
    if not isinstance(scenario, str):
        raise TypeError("scenario: a built-in name, a path, YAML text or a dict, got %s" % type(scenario).__name__)
    if "\n" in scenario or ":" in scenario and not _os.path.exists(scenario):
        return scenario, "scenario (YAML text)"
    return scenario, ""


def _integer(name, value):
    """An integer argument (numpy integers too); TypeError for a float, a bool or anything else."""
    if isinstance(value, bool):
        raise TypeError("%s must be an integer, got bool %r" % (name, value))
    try:
        return _operator.index(value)
    except TypeError:
        raise TypeError("%s must be an integer, got %s %r" % (name, type(value).__name__, value)) from None


def _flag(name, value):
    if not isinstance(value, (bool, _np.bool_)):
        raise TypeError("%s must be True or False, got %s %r" % (name, type(value).__name__, value))
    return bool(value)


class TruthRecord(dict):
    """A Simbody truth: ``{"t": times [s], column: values, ...}``; ``meta`` is its truth.json (a dict:
    true parameters, each column's unit, kind and noise level)."""

    def __init__(self, columns, meta):
        """columns: {"t": times, name: values}; meta: the truth.json dict."""
        super().__init__(columns)
        self.meta = meta

    def to_dataframe(self):
        """The record as a pandas DataFrame indexed by ``t`` (its ``attrs["meta"]`` the truth.json)."""
        import pandas as pd
        df = pd.DataFrame({k: v for k, v in self.items() if k != "t"}, index=pd.Index(self["t"], name="t"))
        df.attrs["meta"] = self.meta
        return df

    def __reduce__(self):
        return (TruthRecord, (dict(self), self.meta))


def truth(scenario, progress=False):
    """The Simbody truth of a scenario, as ``scole-truth`` computes it (the same numbers).

    Args:
        scenario (str | os.PathLike | dict): a built-in name, a path, YAML text or a dict.
        progress (bool): print the simulation's progress on stderr.
    Returns:
        TruthRecord: ``{"t": times, column: values}`` with ``meta`` (truth.json).
    Raises:
        InputError: an invalid scenario.
    """
    text, source = _scenario(scenario)
    (names, t, values), meta = _core.truth(text, source, _flag("progress", progress))
    cols = {"t": t}
    for j, n in enumerate(names):
        cols[n] = _np.ascontiguousarray(values[:, j])
    return TruthRecord(cols, _json.loads(meta))


def _path(name, value):
    """A file path argument (str or os.PathLike); TypeError for anything else."""
    if isinstance(value, (str, _os.PathLike)):
        return _os.fspath(value)
    raise TypeError("%s must be a path (str or os.PathLike), got %s %r" % (name, type(value).__name__, value))


def _text(name, value, allow_none=True):
    if value is None and allow_none:
        return ""
    if not isinstance(value, str):
        raise TypeError("%s must be a str, got %s %r" % (name, type(value).__name__, value))
    return value


def _number(name, value, default):
    if value is None:
        return default
    if isinstance(value, bool) or not isinstance(value, (int, float, _np.integer, _np.floating)):
        raise TypeError("%s must be a number, got %s %r" % (name, type(value).__name__, value))
    return float(value)


def read_data(path, *, time_column=None, time_unit=None):
    """A measured record as ``scole-identify --data`` reads it: a CSV (DAQ dialects), a Universal
    File (58/58b time responses), a LabVIEW LVM or an NI TDMS file.

    Args:
        path (str | os.PathLike): the data file.
        time_column (str): a CSV's time column header (default: the first column).
        time_unit (str): a CSV time column's unit when its header states none (default: s).

    Returns:
        pandas.DataFrame: one column per channel in the file's order, values in the file's units,
        indexed by ``t`` in seconds; ``attrs["units"]`` maps each column to its unit as the file
        states it ("" where it states none) and ``attrs["source"]`` is the path.

    Raises:
        InputError: the file cannot be read (one line naming it, the line or record, field and value).
    """
    import pandas as pd
    path = _path("path", path)
    names, units, t, values = _core.read_data(path, _text("time_column", time_column), _text("time_unit", time_unit))
    df = pd.DataFrame(values, columns=names, index=pd.Index(t, name="t"))
    df.attrs["units"] = dict(zip(names, units))
    df.attrs["source"] = path
    return df


class Frf:
    """Frequency responses of a record's responses to its force (``scoleid.frf``), in SI per N.

    Attributes:
        H (pandas.DataFrame): complex H per response column, indexed by ``f_hz``.
        std (pandas.DataFrame): each value's standard deviation, sqrt(E|Ĥ − H|²).
        coherence (pandas.DataFrame | None): γ² per value (Welch), None for harmonic lines.
        orders (dict): per response 0 displacement, 1 velocity, 2 acceleration (its unit's).
        sample_rate (float), samples (int), segments (int, 0 for lines and impact),
        effective_averages (float), note (str): how they were made.
        decay (float): the impact estimator's exponential window, 1/s: the values are H at
            s = decay + iω (0 for the others: at iω).
    """

    def __init__(self, H, std, coherence, orders, sample_rate, samples, segments, effective_averages, note, decay=0.0):
        self.H, self.std, self.coherence, self.orders = H, std, coherence, orders
        self.sample_rate, self.samples, self.segments = sample_rate, samples, segments
        self.effective_averages, self.note, self.decay = effective_averages, note, decay

    def __repr__(self):
        return "<scoleid.Frf %d responses x %d lines: %s>" % (self.H.shape[1], self.H.shape[0], self.note)


def frf(path, input, responses=None, *, units=None, sample_rate=None, estimator="h1", segment=None, overlap=0.5,
        window="hann", f_min=None, f_max=None, lines=None, time_column=None, time_unit=None, decay=None, noise=None):
    """Frequency response functions of a data file's response columns to its force column, as
    ``scole-data frf`` makes them (docs/data.md §1.7): Welch H1/H2 with the record streamed (a CSV
    of any length is never held whole), the harmonic fit of known lines, or one hit's FRF under an
    exponential window (impact).

    Args:
        path (str | os.PathLike): the record (CSV, UFF, LVM or TDMS).
        input (str): the force column's name.
        responses (list[str]): response columns (default: every column but the input).
        units (dict): column -> unit, for columns whose file states none.
        sample_rate (float): the DAQ's rate in Hz (default: from the time column).
        estimator (str): "h1" (default), "h2", "lines" or "impact" (one hit from rest, the record one
            segment under e^{-decay t}: H at s = decay + iω, ``Frf.decay``).
        segment (float): Welch segment in s (default: a power of two of samples near the record / 4.5).
        overlap (float): Welch overlap in [0, 1) (default 0.5).
        window (str): "hann" (default) or "rectangular".
        f_min, f_max (float): the lines kept, f_min < f <= f_max (default 0 to 0.8 of Nyquist).
        lines (list[float]): the input's frequencies in Hz, for estimator "lines".
        time_column, time_unit (str): as ``read_data``.
        decay (float): impact: the window's rate in 1/s (default ln(100)/T, a hundredth at the end).
        noise (dict): impact: column -> noise level in the column's own unit (default: the record's
            quiet start before the hit; refused when it has none).

    Returns:
        Frf: H, std and coherence as DataFrames indexed by ``f_hz``, and how they were made.

    Raises:
        InputError: a bad file, column, unit, clock or option (one line naming it).
        TypeError: an argument of the wrong type.
    """
    import pandas as pd
    path = _path("path", path)
    input = _text("input", input, allow_none=False)
    if responses is None:
        responses = []
    elif isinstance(responses, str) or not all(isinstance(r, str) for r in responses):
        raise TypeError("responses must be a list of column names, got %r" % (responses,))
    if units is None:
        units = {}
    elif not hasattr(units, "items") or not all(isinstance(k, str) and isinstance(v, str) for k, v in units.items()):
        raise TypeError("units must be a dict of column name -> unit text, got %r" % (units,))
    if lines is None:
        lines = []
    else:
        lines = [_number("lines[%d]" % i, f, None) for i, f in enumerate(lines)]
    if noise is None:
        noise = {}
    elif not hasattr(noise, "items") or not all(isinstance(k, str) for k in noise):
        raise TypeError("noise must be a dict of column name -> noise level, got %r" % (noise,))
    noise = {k: _number("noise[%r]" % k, v, float("nan")) for k, v in noise.items()}
    f, names, H, var, coh, orders, rate, samples, segments, keff, note, decay_used = _core.frf(
        path, input, list(responses), dict(units), _number("sample_rate", sample_rate, 0.0),
        _text("estimator", estimator, allow_none=False), _number("segment", segment, 0.0), _number("overlap", overlap, 0.5),
        _text("window", window, allow_none=False), _number("f_min", f_min, 0.0), _number("f_max", f_max, 0.0), lines,
        _text("time_column", time_column), _text("time_unit", time_unit), _number("decay", decay, -1.0), noise)
    index = pd.Index(f, name="f_hz")
    return Frf(pd.DataFrame(H, columns=names, index=index), pd.DataFrame(_np.sqrt(var), columns=names, index=index),
               None if coh is None else pd.DataFrame(coh, columns=names, index=index), dict(zip(names, orders)), rate, samples,
               segments, keff, note, decay_used)


def _dtype_kind(values):
    return getattr(getattr(values, "dtype", None), "kind", "")


def _column(name, values, n=None):
    """One column as a 1-D float array of n values; InputError for anything else."""
    if _dtype_kind(values) == "M":
        raise InputError("data: column '%s' holds dates (%s); give the time as seconds or time spans "
                         "(e.g. df.index - df.index[0])" % (name, values.dtype))
    if _dtype_kind(values) == "m":
        raise InputError("data: column '%s' holds time spans (%s); only the time may" % (name, values.dtype))
    if _dtype_kind(values) == "c" or (
            getattr(values, "dtype", None) == object and any(isinstance(x, (complex, _np.complexfloating)) for x in values)):
        raise InputError("data: column '%s' is complex; give real values (a time record)" % name)
    if hasattr(values, "to_numpy"):  # a pandas Series or Index (nullable dtypes: NA becomes NaN, refused later)
        try:
            values = values.to_numpy(dtype=float, na_value=_np.nan)
        except (TypeError, ValueError) as e:
            raise InputError("data: column '%s' is not numeric (%s)" % (name, e)) from None
    a = _np.asarray(values)
    if _np.iscomplexobj(a) or (a.dtype == object and any(isinstance(x, (complex, _np.complexfloating)) for x in a.ravel())):
        raise InputError("data: column '%s' is complex; give real values (a time record)" % name)
    if a.dtype.kind in "mM":
        raise InputError("data: column '%s' holds dates or time spans (%s); give seconds as numbers" % (name, a.dtype))
    try:
        a = _np.asarray(a, dtype=float)
    except (TypeError, ValueError) as e:
        raise InputError("data: column '%s' is not numeric (%s)" % (name, e)) from None
    if a.ndim != 1:
        raise InputError("data: column '%s' has shape %s; give a 1-D array%s"
                         % (name, a.shape, "" if n is None else " of %d values" % n))
    if n is not None and a.size != n:
        raise InputError("data: column '%s' has %d values for %d times" % (name, a.size, n))
    return a


_UNIT = _re.compile(r"\[\s*([^\]]*?)\s*\]\s*$")


def _time_column(name, values):
    """(header name, seconds-or-stated-unit values) of the time: a Timedelta time in seconds."""
    kind = _dtype_kind(values)
    if kind == "M":
        raise InputError("data: the time '%s' holds dates (%s); give seconds or time spans from the start "
                         "(e.g. df.index - df.index[0])" % (name, values.dtype))
    if kind != "m":
        return name, _column(name, values)
    m = _UNIT.search(name)
    if m and m.group(1) not in ("", "s"):
        raise InputError("data: the time '%s' holds time spans, which are seconds, not [%s]" % (name, m.group(1)))
    if hasattr(values, "isna") and bool(values.isna().any()):
        raise InputError("data: the time '%s' has missing values (NaT)" % name)
    seconds = _np.asarray(values, dtype="timedelta64[ns]").astype(_np.int64) / 1e9
    return (_UNIT.sub("", name).rstrip() or "t") + " [s]", seconds


_TIME_NAME = _re.compile(r"^\s*(t|time|zeit|temps)\b", _re.IGNORECASE)


def _index_is_time(index):
    """A DataFrame's index is its time when it holds floats, time spans or dates, or when it holds
    integers under a time's name ("t", "time", a bracketed unit such as "t [ms]"). An integer index
    under any other name ("sample", "row") counts rows, not time."""
    if index.dtype.kind in "fmM":
        return True
    name = index.name
    return (index.dtype.kind in "iu" and isinstance(name, str)
            and (_TIME_NAME.match(name) is not None or _UNIT.search(name) is not None))


def _is_text(values):
    """A column of words (strings, categories of strings), not numbers."""
    kind = _dtype_kind(values)
    if kind in ("U", "S"):
        return True
    if kind == "O" or str(getattr(values, "dtype", "")) in ("string", "category"):
        try:
            _np.asarray(values, dtype=float)
        except (TypeError, ValueError):
            return True
    return False


def _table(data, time, wanted=None):
    """(header, values[samples x columns], time column, source, meta_json, meta_source) of a dict or
    DataFrame. A text column that no sensor or input reads (`wanted`: their names and columns) is
    left out, as a file's unused columns are."""
    columns, time_name, source, meta_source = {}, "", "data", "data (truth metadata)"
    if hasattr(data, "columns") and hasattr(data, "index") and hasattr(data, "to_numpy"):  # a pandas DataFrame
        source = "data (DataFrame)"
        meta = getattr(data, "attrs", {}).get("meta")
        meta_source = ("data.attrs['meta'] (the truth.json the DataFrame carries: delete it, "
                       "del df.attrs['meta'], when its columns were renamed or dropped)")
        names = [str(c) for c in data.columns]
        if len(set(names)) != len(names):
            raise InputError("data: the DataFrame's column names repeat")
        if len(names) == 0:
            raise InputError("data: the DataFrame has no columns")
        columns = {str(c): data[c] for c in data.columns}
        if time is None and _index_is_time(data.index):
            name = "t" if data.index.name is None else str(data.index.name)
            if name in columns or "t" in columns:
                raise InputError("data: the DataFrame has a time index%s and a column '%s'; which is the time? "
                                 "(pass time='%s', or reset the index)"
                                 % ("" if data.index.name is None else " '%s'" % name, name if name in columns else "t",
                                    name if name in columns else "t"))
            time_name, values = _time_column(name, data.index)
            columns = {time_name: values, **columns}
    elif isinstance(data, dict):
        source = "data (dict)"
        meta = data.meta if isinstance(data, TruthRecord) else None
        meta_source = "TruthRecord.meta (the record's truth.json)"
        if not data:
            raise InputError("data: the dict has no columns")
        columns = {str(k): v for k, v in data.items()}
        if len(columns) != len(data):
            raise InputError("data: the dict's keys repeat once written as text")
    else:
        raise TypeError("data: None, a file path, a dict of arrays or a pandas DataFrame, got %s" % type(data).__name__)
    if time is not None:
        if isinstance(time, str):
            if time not in columns:
                raise InputError("data: time='%s' is not a column (%s)" % (time, ", ".join(list(columns)[:12])))
            time_name, values = _time_column(time, columns.pop(time))
        elif _np.ndim(time) == 1 and not isinstance(time, (bytes, dict)):  # the sample times themselves
            time_name, values = _time_column(str(getattr(time, "name", None) or "t"), time)
            if time_name in columns:
                raise InputError("data: time= gives the times, and the table has a column '%s' already: "
                                 "pass time='%s', or leave that column out" % (time_name, time_name))
        else:
            raise TypeError("time= names the time column (a str) or gives the sample times (a 1-D array), got %s"
                            % type(time).__name__)
        columns = {time_name: values, **columns}
    if wanted is not None:
        for name in [n for n in columns if n != time_name and _is_text(columns[n])]:
            if name not in wanted and _UNIT.sub("", name).rstrip() not in wanted:
                del columns[name]
    header = list(columns)
    n = None
    values = None
    for j, name in enumerate(header):
        v = columns[name]
        if name != time_name:
            if _dtype_kind(v) == "m":
                raise InputError("data: column '%s' holds time spans; pass time='%s' to take it as the time" % (name, name))
            v = _column(name, v, n)
        if values is None:
            n = len(v)
            values = _np.empty((n, len(header)))
        values[:, j] = v
    return header, values, time_name, source, _json.dumps(meta) if meta is not None else "", meta_source


class StateSpace:
    """The identified linear FE model as a plant: x' = A x + B f, y = C x + D f, with x = (u, du/dt) the
    FE model's degrees of freedom and their rates, f the scenario's inputs and y its sensors, in the
    scenario's units (``input_units``, ``output_units``). ``to_scipy()`` gives a
    ``scipy.signal.StateSpace`` (whose rows and columns follow ``inputs`` and ``outputs``)."""

    def __init__(self, A, B, C, D, inputs, outputs, input_units=(), output_units=()):
        """A, B, C, D: the matrices (numpy); inputs, outputs: their names; input_units, output_units: their units."""
        self.A, self.B, self.C, self.D = A, B, C, D
        self.inputs, self.outputs = list(inputs), list(outputs)
        self.input_units, self.output_units = list(input_units), list(output_units)

    def to_scipy(self):
        """``scipy.signal.StateSpace(A, B, C, D)``, continuous time."""
        from scipy import signal
        return signal.StateSpace(self.A, self.B, self.C, self.D)

    def __repr__(self):
        return "<scoleid.StateSpace %d states, inputs %s, outputs %s>" % (self.A.shape[0], self.inputs, self.outputs)


def _interval_pair(i):
    return (i["low"], i["high"]) if isinstance(i, dict) and "low" in i else None


class Identification:
    """One identification: estimates with their std and intervals, the verdict it earned, the model.

    Built by ``identify()``. Everything is read from the run's identify.json (``to_dict()``); tables
    come as pandas DataFrames (``summary()``, ``fit``, ``modes``). It pickles with all its numbers;
    ``write()`` and ``export_model()`` need the solver's state and work only in the process that ran it.
    """

    def __init__(self, core, library_seconds=float("nan")):
        """Made by identify(); core is the library's result, library_seconds the call's duration."""
        self._core = core
        self._json_text = core.to_json()
        self._dict = _json.loads(self._json_text)
        self._cache = {}
        #: seconds the library call took (scenario to verdict), without the Python around it
        self.library_seconds = library_seconds
        self._plain = {"converged": core.converged, "verdict": core.verdict, "exit_code": core.exit_code,
                       "warnings": list(core.warnings), "names": list(core.names), "report": core.report()}

    # ----- pickling: the numbers travel, the solver's state does not
    def __getstate__(self):
        self._fit_arrays()
        self._model_arrays()
        return {"json_text": self._json_text, "cache": self._cache, "plain": self._plain,
                "library_seconds": self.library_seconds}

    def __setstate__(self, state):
        self._core = None
        self._json_text = state["json_text"]
        self._dict = _json.loads(self._json_text)
        self._cache = state["cache"]
        self._plain = state["plain"]
        self.library_seconds = state["library_seconds"]

    def __copy__(self):
        other = Identification.__new__(Identification)
        other.__dict__.update(self.__dict__)
        return other

    def __deepcopy__(self, memo):
        import copy
        other = Identification.__new__(Identification)
        for k, v in self.__dict__.items():
            other.__dict__[k] = v if k == "_core" else copy.deepcopy(v, memo)  # the solver's state is immutable: shared
        return other

    def _need_core(self, what):
        if self._core is None:
            raise RuntimeError("%s needs the solver's state, which an unpickled Identification does not carry: "
                               "call it in the process that ran identify()" % what)
        return self._core

    def _fit_arrays(self):
        if "fit" not in self._cache:
            self._cache["fit"] = self._need_core("fit").fit_table()
        return self._cache["fit"]

    def _model_arrays(self):
        if "state_space" not in self._cache:
            core = self._need_core("state_space()")
            self._cache["state_space"] = dict(core.state_space())
            self._cache["modal_model"] = dict(core.modal_model())
            self._cache["model_json"] = core.model_json()
        return self._cache

    # ----- verdict
    @property
    def converged(self):
        """True only when the optimiser converged and the model explains the data (the fit test)."""
        return self._plain["converged"]

    @property
    def verdict(self):
        """Why the run is not converged, in one line ("" when it is)."""
        return self._plain["verdict"]

    @property
    def exit_code(self):
        """scole-identify's exit code for this run: 0 when converged, 1 otherwise."""
        return self._plain["exit_code"]

    @property
    def warnings(self):
        """What the user must know even of a converged run (list of str; also emitted as ScoleidWarning)."""
        return list(self._plain["warnings"])

    # ----- estimates
    @property
    def names(self):
        """The estimated parameters' names (list of str), in the order of every table."""
        return list(self._plain["names"])

    @property
    def estimates(self):
        """``{parameter: estimate}``"""
        return {p["name"]: p["estimate"] for p in self._dict["parameters"]}

    @property
    def physical(self):
        """The structure's physical values at the estimate (EI, rho_A, zeta, ...), as a dict (a copy)."""
        return _json.loads(_json.dumps(self._dict["physical_estimate"]))

    @property
    def std(self):
        """``{parameter: standard deviation}`` (None where not assessed or not identifiable)."""
        return {p["name"]: p.get("std") for p in self._dict["parameters"]}

    @property
    def intervals(self):
        """``{parameter: (low, high)}`` of the reported uncertainty interval (None where there is none)."""
        return {p["name"]: _interval_pair(p.get("interval")) for p in self._dict["parameters"]}

    @property
    def identifiable(self):
        """``{parameter: bool}`` (None where not assessed: ``compute_std=False``)."""
        return {p["name"]: p.get("identifiable") for p in self._dict["parameters"]}

    def summary(self):
        """identify.json's parameters as a DataFrame indexed by name: initial, estimate, std, low, high,
        identifiable (and truth, relative_error when the record states the true values). Missing values
        (not assessed, not identifiable) are NaN / None.

        Returns:
            pandas.DataFrame
        """
        import pandas as pd
        rows = []
        for p in self._dict["parameters"]:
            low, high = _interval_pair(p.get("interval")) or (None, None)
            row = {"initial": p["initial"], "estimate": p["estimate"], "std": p.get("std"), "low": low, "high": high,
                   "identifiable": p.get("identifiable")}
            if "truth" in p:
                row.update({"truth": p["truth"], "relative_error": p["relative_error"]})
            rows.append(row)
        df = pd.DataFrame(rows, index=pd.Index([p["name"] for p in self._dict["parameters"]], name="parameter"))
        for c in ("initial", "estimate", "std", "low", "high", "truth", "relative_error"):
            if c in df:
                df[c] = df[c].astype(float)
        return df

    @property
    def modes(self):
        """The identified model's elastic modes, lowest first, as a DataFrame indexed by mode number:
        frequency_hz, frequency_std_hz, frequency_low_hz, frequency_high_hz (the uncertainty interval),
        damping_ratio, damping_ratio_std, damping_ratio_low, damping_ratio_high; NaN where not
        assessed, with the reason in ``uncertainty_not_given_because`` (docs/theory.md §8.3). The
        record's own mode (§8.4: where the record places it, freed from the model's form):
        record_frequency_hz, record_frequency_std_hz, record_damping_ratio, record_damping_ratio_std,
        and the model-form terms the interval holds, frequency_model_form_hz and
        damping_ratio_model_form (0 where none; NaN where the mode was not freed).
        Rigid-body modes are not listed (``modal_model()`` flags them)."""
        import pandas as pd
        rows = []
        for m in self._dict.get("modes", []):
            def num(k):
                v = m.get(k)
                return _math.nan if v is None else float(v)
            f, hw, z, zhw = num("frequency_hz"), num("frequency_interval_hz"), num("damping_ratio"), num("damping_ratio_interval")
            rows.append({"mode": m["mode"], "frequency_hz": f, "frequency_std_hz": num("frequency_std_hz"),
                         "frequency_low_hz": f - hw, "frequency_high_hz": f + hw,
                         "damping_ratio": z, "damping_ratio_std": num("damping_ratio_std"),
                         "damping_ratio_low": z - zhw, "damping_ratio_high": z + zhw,
                         "uncertainty_not_given_because": m.get("uncertainty_not_given_because", "")})
            rec = m.get("record") or {}
            for k in ("frequency_hz", "frequency_std_hz", "damping_ratio", "damping_ratio_std"):
                v = rec.get(k)
                rows[-1]["record_" + k] = _math.nan if v is None else float(v)
            for k in ("frequency_model_form_hz", "damping_ratio_model_form"):
                v = rec.get(k)
                rows[-1][k] = _math.nan if v is None else float(v)
        cols = ["frequency_hz", "frequency_std_hz", "frequency_low_hz", "frequency_high_hz", "damping_ratio",
                "damping_ratio_std", "damping_ratio_low", "damping_ratio_high", "uncertainty_not_given_because",
                "record_frequency_hz", "record_frequency_std_hz", "record_damping_ratio", "record_damping_ratio_std",
                "frequency_model_form_hz", "damping_ratio_model_form"]
        if not rows:
            return pd.DataFrame(columns=cols, index=pd.Index([], name="mode"))
        return pd.DataFrame(rows).set_index("mode")[cols]

    @property
    def correlation(self):
        """The correlation matrix of the estimates as ``{parameter: {parameter: r}}`` (None where a
        parameter has no covariance; {} when not assessed)."""
        c = self._dict.get("identifiability", {}).get("correlation")
        if not c:
            return {}
        names = c["parameters"]
        return {a: {b: c["matrix"][i][j] for j, b in enumerate(names)} for i, a in enumerate(names)}

    @property
    def iterations(self):
        """The iteration history, as identify.json's "iterations" (list of dict; a copy)."""
        return _json.loads(_json.dumps(self._dict.get("iterations", [])))

    # ----- the fit
    @property
    def fit(self):
        """fit.csv as a DataFrame indexed by ``t`` [s]: per sensor ``<name>_measured``,
        ``<name>_predicted`` and ``<name>_residual`` (predicted − measured), in the scenario's units."""
        import pandas as pd
        names, t, values = self._fit_arrays()
        return pd.DataFrame(_np.array(values, copy=True), columns=list(names), index=pd.Index(_np.array(t), name="t"))

    # ----- outputs
    def to_json(self, indent=None):
        """identify.json's content as JSON text: compact (``indent=None``), or indented as ``json.dumps``
        indents (the file ``write()`` makes holds the same content)."""
        return self._json_text if indent is None else _json.dumps(self._dict, indent=indent)

    def to_dict(self):
        """identify.json as a dict (a fresh copy)."""
        return _json.loads(self._json_text)

    def report(self):
        """The table scole-identify prints (str)."""
        return self._plain["report"]

    def state_space(self):
        """The identified linear FE model as a plant.

        Returns:
            StateSpace: A, B, C, D (numpy arrays), inputs, outputs and their units; ``to_scipy()``.
        """
        c = self._model_arrays()
        ss, model = c["state_space"], _json.loads(c["model_json"])["state_space"]
        return StateSpace(_np.array(ss["A"]), _np.array(ss["B"]), _np.array(ss["C"]), _np.array(ss["D"]), ss["inputs"],
                          ss["outputs"], model.get("input_units", ()), model.get("output_units", ()))

    def modal_model(self):
        """The identified model's modes, all of them (rigid-body modes too), ascending.

        Returns:
            dict: ``omega`` [rad/s], ``zeta`` (NaN for a rigid-body mode), ``rigid`` (bool array: a mode
            whose frequency is under 1e-6 of the highest, at ω ~ 0: a free structure's rigid motions —
            six for a free body such as SCOLE, plus one per proof-mass actuator on its slider, and
            each one's rotation where the model has it),
            ``output_shapes`` (outputs x modes: a sensor's reading per unit modal coordinate),
            ``input_shapes`` (inputs x modes), ``inputs``, ``outputs``.
        """
        m = {k: (_np.array(v) if isinstance(v, _np.ndarray) else list(v)) for k, v in self._model_arrays()["modal_model"].items()}
        m["rigid"] = ~_np.isfinite(_np.asarray(m["zeta"], dtype=float))
        return m

    def export_model(self, path):
        """The state space and the modal model to ``path`` (.json, or .mat for MATLAB: A, B, C, D, inputs,
        outputs, omega, zeta, output_shapes, input_shapes), as ``scole-identify --export-model`` writes
        them.

        Returns:
            dict: the model as written to .json.
        Raises:
            InputError: another extension, a path that is an input of the run, a directory.
            RuntimeError: an unpickled Identification (no solver state).
        """
        self._need_core("export_model()").export_model(_os.fspath(path))
        return _json.loads(self._model_arrays()["model_json"])

    def write(self, directory):
        """identify.json, fit.csv, fit.gp, spectrum.csv, spectrum.gp (and fit.png, spectrum.png with
        gnuplot; on a measured record with one input from the data also start_frf.csv, start_frf.gp,
        start_frf.png) into ``directory``, as ``scole-identify --out`` writes them (all or none).

        Raises:
            InputError: the directory holds an input of the run, or another run is writing into it.
            RuntimeError: an unpickled Identification (no solver state).
        """
        self._need_core("write()").write(_os.fspath(directory))

    def __repr__(self):
        return "<scoleid.Identification %s: %s>" % (
            ", ".join("%s=%.6g" % kv for kv in self.estimates.items()),
            "converged" if self.converged else "not converged (%s)" % self.verdict)


def _progress_sink(progress, verbose):
    """One callable for the library's progress lines, or None when nobody listens."""
    sinks = []
    if progress is not None:
        if not callable(progress):
            raise TypeError("progress must be a callable taking one line (str), got %s" % type(progress).__name__)
        sinks.append(progress)
    if verbose:
        sinks.append(lambda line: print(line, file=_sys.stdout, flush=True))
    if _log.isEnabledFor(_logging.INFO):
        sinks.append(_log.info)
    if not sinks:
        return None

    def sink(line):
        for s in sinks:
            s(line)
    return sink


def identify(scenario, data=None, *, time=None, method=None, max_iterations=None, compute_std=True, verbose=False,
             progress=None):
    """Identify the scenario's parameters from data, as ``scole-identify`` does (the same numbers).

    Args:
        scenario (str | os.PathLike | dict): a built-in name, a scenario file, YAML text or a dict.
        data (None | str | os.PathLike | dict | pandas.DataFrame): None: the scenario synthesises its
            data (on a finer mesh); a file: CSV, Universal File or LabVIEW LVM; a dict of equal-length
            arrays; a DataFrame. See the module's help for how the time and the units are found.
        time (None | str | array): the time column's name, or the sample times themselves (seconds, or
            time spans); None: the DataFrame's index when it is time, else as a CSV file's.
        method (None | str): the optimiser: "auto", "gauss-newton", "gauss-newton-krylov", "lbfgs" or
            "steepest-descent" (scole-identify --help); None: the scenario's identification.method.
        max_iterations (None | int): None: the scenario's identification.max_iterations.
        compute_std (bool): identifiability, standard deviations and uncertainty intervals.
        verbose (bool): print the progress (iteration table, restarts, fit test) on sys.stdout.
        progress (None | callable): called with each progress line (str) as the run goes; an exception it
            raises ends the run and is raised in its place. It may not call the library itself
            (RuntimeError).
    Returns:
        Identification: the estimates and the verdict. ``converged`` is True only when earned; a run that
        is not converged, or whose parameters the data do not determine, also emits a ScoleidWarning.
    Raises:
        InputError: a bad scenario field, data column, unit or file (one line naming it), before any solve.
        TypeError: an argument of the wrong type.
        KeyboardInterrupt: Ctrl-C (or SIGTERM) during the run.
    """
    text, source = _scenario(scenario)
    args = _core.IdentifyArgs()
    if data is None:
        if time is not None:
            raise TypeError("time= applies to a table (a dict or a DataFrame), not to synthesised data")
    elif isinstance(data, (str, _os.PathLike)):
        if time is not None:
            raise TypeError("time= applies to a table; a file's time column is the scenario's data.time_column")
        args.data_file = _os.fspath(data)
    else:
        spec = _json.loads(_core.scenario_json(text, source))
        wanted = {x.get(k) for x in spec.get("sensors", []) + spec.get("inputs", []) for k in ("name", "column")} - {None}
        args.header, args.values, args.time_column, args.source, args.meta_json, args.meta_source = _table(data, time, wanted)
    if method is not None and not isinstance(method, str):
        raise TypeError("method must be a str, got %s" % type(method).__name__)
    args.method = method
    if max_iterations is not None:
        max_iterations = _integer("max_iterations", max_iterations)
        if not 0 <= max_iterations <= 2**31 - 1:
            raise InputError("identify: max_iterations must be between 0 and 2147483647, got %d" % max_iterations)
    args.max_iterations = max_iterations
    args.compute_std = _flag("compute_std", compute_std)
    _flag("verbose", verbose)
    sink = _progress_sink(progress, verbose)
    if sink is not None:
        args.progress = sink
    core, seconds = _core.identify(text, source, args)
    idn = Identification(core, seconds)
    for w in idn.warnings:
        _warnings.warn(w, ScoleidWarning, stacklevel=2)
    if not idn.converged:
        _warnings.warn("not converged: " + idn.verdict, ScoleidWarning, stacklevel=2)
    return idn


def crosscheck_modes(scenario, count=10, segments=0, elements=0, levels=3):
    """The Simbody chain's modes against the FE model's (``scole-crosscheck modes``).

    Args:
        scenario: a built-in name, a path, YAML text or a dict.
        count (int): modes compared.  segments, elements (int): 0 = the scenario's.
        levels (int): refinement levels of the extrapolation.
    Returns:
        dict: the report, as ``scole-crosscheck modes`` writes it.
    """
    text, source = _scenario(scenario)
    return _json.loads(_core.crosscheck_modes(text, source, _integer("count", count), _integer("segments", segments),
                                              _integer("elements", elements), _integer("levels", levels)))


def crosscheck_trajectories(scenario, truth_dir, segments=0, levels=3, elements=0):
    """The chain's and the FE model's sensor records side by side (``scole-crosscheck trajectories``).

    Args:
        scenario: a built-in name, a path, YAML text or a dict.
        truth_dir (str | os.PathLike): where the truths of the chain levels are (made when missing).
        segments, elements (int): 0 = the scenario's.  levels (int): chain refinement levels.
    Returns:
        dict: the report, with "t", "chain" and "fe" (samples x sensors, finest level) as arrays.
    """
    text, source = _scenario(scenario)
    report, t, chain, fe = _core.crosscheck_trajectories(text, source, _integer("segments", segments),
                                                         _integer("levels", levels), _integer("elements", elements),
                                                         _os.fspath(truth_dir))
    out = _json.loads(report)
    out.update({"t": t, "chain": chain, "fe": fe})
    return out

