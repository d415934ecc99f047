"""tricept: self-calibration of the Tricept parallel kinematic machine.

Machines and batch kinematics on numpy arrays, computed by the same Rust
library as the ``tricept`` command line (lengths in mm, angles in rad)::

    import numpy as np, tricept
    m = tricept.Machine.paper()
    q = m.ik(np.array([[0.0, 0.0, 750.0]]))   # (1, 6): q1, q2, q3, phi, theta, q4

Arrays are read in place when they are C-contiguous float64 (anything else
is converted once); the points are solved in parallel with the GIL released.
Bad input raises :class:`InputError`, a :class:`ValueError`; a file that
cannot be read or written the operating system's :class:`OSError`
subclass; memory that cannot hold a result :class:`MemoryError`.

The workflows are the CLI's, through the same library calls:
:func:`identify` (``tricept identify``), :func:`diagnose`, :func:`check`,
:func:`simulate` and :func:`report`. Data are a CSV path or a mapping of the CSV's column names
to 1-D arrays (a pandas DataFrame is one); ``machine`` is a machine file's
path or a :class:`Machine`. Results carry the CLI's exit code,
``to_json()`` is the CLI's ``--json``, and results and machines pickle.
"""

import json
import numbers
import os
from typing import Any, Dict, Mapping, Optional, Sequence, Union

import numpy as np

from . import _tricept
from ._errors import InputError, UntrustedError

__version__: str = _tricept.__version__

__all__ = [
    "__version__",
    "InputError",
    "UntrustedError",
    "Machine",
    "Calibration",
    "Diagnosis",
    "CheckResult",
    "Fleet",
    "identify",
    "fleet",
    "diagnose",
    "check",
    "simulate",
    "report",
]

PathLike = Union[str, os.PathLike]

# Integer options and their ranges (what the compiled half can hold).
_INT_RANGES = {
    "readings_per_pose": (1, 2**32 - 1),
    "seed": (0, 2**64 - 1),
    "revisit": (0, 1_000_000),
}


def _int_options(options: Dict[str, Any]) -> Dict[str, Any]:
    """``options`` with each integer option checked: a value out of its
    range is an :class:`InputError` (a negative seed, a count of -1), a
    value that is not an integer a :class:`TypeError`."""
    for name, (low, high) in _INT_RANGES.items():
        if name not in options or options[name] is None:
            continue
        value = options[name]
        if isinstance(value, bool) or not isinstance(value, numbers.Integral):
            raise TypeError(f"{name}: expected an integer, got {type(value).__name__}")
        value = int(value)
        if not low <= value <= high:
            raise InputError(f"{name}: must be an integer from {low} to {high}, got {value}")
        options[name] = value
    return options


def _machine_arg(machine) -> Any:
    """The machine argument as the compiled half takes it: ``None`` (the
    built-in Table 1 machine), a path, or a compiled machine."""
    if machine is None:
        return None
    if isinstance(machine, Machine):
        return machine._machine
    if isinstance(machine, (str, os.PathLike)):
        return os.fspath(machine)
    raise InputError(
        f"machine: expected a machine file (a path) or a tricept.Machine, got {type(machine).__name__}"
    )


def _data(data) -> dict:
    """The data argument as keyword arguments of the compiled workflows:
    a path, or CSV text written from a mapping of column arrays with
    shortest round-trip numbers (the same float64 bits). Array row ``i`` is
    the CSV's line ``i + 2``; messages name it as ``row i``."""
    if isinstance(data, (str, os.PathLike)):
        return {"path": os.fspath(data)}
    try:
        names = [str(k) for k in data.keys()]
    except AttributeError:
        raise InputError("data: expected a CSV path or a mapping of column names to arrays") from None
    columns = []
    for k in names:
        if any(c in k for c in ",\n\r") or not k.strip():
            raise InputError(f"data: column name {k!r} is not one a CSV header can hold")
        c = np.asarray(data[k])
        if c.ndim != 1:
            raise InputError(f"data: column `{k}` is not one-dimensional (shape {c.shape})")
        columns.append(c)
    n = {len(c) for c in columns}
    if len(n) > 1:
        raise InputError(f"data: the columns have different lengths {sorted(n)}")
    lines = [",".join(names)]
    for i, row in enumerate(zip(*columns)):
        cells = [_cell(v) for v in row]
        for k, cell in zip(names, cells):
            if any(c in cell for c in ",\n\r"):
                raise InputError(f"data: row {i}, column `{k}`: not a number (got {cell!r})")
        lines.append(",".join(cells))
    return {"csv_text": "\n".join(lines) + "\n"}


def _cell(v) -> str:
    if isinstance(v, (float, np.floating)):
        return repr(float(v))
    if isinstance(v, (bool, np.bool_)):
        return "1" if v else "0"
    return str(v)


class _Frozen:
    """A result read back from a pickle: what the live result gave, kept
    as data (its JSON, report, numbers, the machine file it may write)."""

    def __init__(self, state: Dict[str, Any]):
        self.__dict__.update(state)


def _machine_file_state(compiled) -> Dict[str, Any]:
    """The machine file a live result may write (``machine_file``), or why
    there is none (``machine_file_error``), for its pickled state."""
    try:
        return {"machine_file": compiled.machine_file_json(), "machine_file_error": None}
    except InputError as e:
        return {"machine_file": None, "machine_file_error": str(e)}


def _write_frozen(state, path: PathLike, force: bool):
    """Writes the machine file a result read back from a pickle kept, by
    the same rule (and with the same refusals) as the live result."""
    if state.machine_file is None:
        raise InputError(state.machine_file_error)
    return _tricept.write_machine_file(state.machine_file, os.fspath(path), force)


class Calibration:
    """A calibration (``tricept identify``): ``exit_code`` (0 trusted, 3
    the model does not explain the data or the campaign is too small, 4 not
    converged), ``estimates`` and ``sd`` by parameter name (mm, rad; an sd
    of ``None`` is a held parameter), ``covariance`` (in the order of
    ``names``), ``warnings``, ``to_json()``, ``report()``,
    ``write_machine(path, force=False)`` and ``machine`` (the calibrated
    :class:`Machine`, in memory). Pickles (the numbers, the JSON, the
    report, the machine and the file it may write)."""

    __slots__ = ("_c",)

    def __init__(self, compiled):
        self._c = compiled

    @property
    def exit_code(self) -> int:
        return self._c.exit_code

    @property
    def names(self) -> "list[str]":
        return list(self._c.names)

    @property
    def estimates(self) -> "dict[str, float]":
        return dict(self._c.estimates)

    @property
    def sd(self) -> "dict[str, Optional[float]]":
        return dict(self._c.sd)

    @property
    def covariance(self) -> np.ndarray:
        return np.array(self._c.covariance, dtype=np.float64)

    @property
    def warnings(self) -> "list[str]":
        return list(self._c.warnings)

    def to_json(self) -> str:
        """The JSON ``tricept identify --json`` prints."""
        c = self._c
        return c.json if isinstance(c, _Frozen) else c.to_json()

    def report(self) -> str:
        """The report ``tricept identify`` prints."""
        c = self._c
        return c.report_text if isinstance(c, _Frozen) else c.report()

    def write_machine(self, path: PathLike, force: bool = False) -> str:
        """Writes the calibrated machine file by the CLI's rule: a result
        that is not to be trusted raises :class:`UntrustedError` unless
        ``force``; a calibration from arrays cannot record its data file
        and raises :class:`InputError`; a folder that does not exist raises
        :class:`FileNotFoundError`."""
        if isinstance(self._c, _Frozen):
            _write_frozen(self._c, path, force)
            return os.fspath(path)
        return self._c.write_machine(os.fspath(path), force)

    @property
    def machine(self) -> "Machine":
        """The calibrated machine, in memory (no file needed): with its
        calibration record when the data came from a file (so that
        :func:`check` can use it), the identified geometry alone when they
        came as arrays."""
        c = self._c
        if isinstance(c, _Frozen):
            return Machine(_tricept.Machine.from_json(c.machine_json, c.machine_source))
        return Machine(c.machine())

    def __reduce__(self):
        c = self._c
        if isinstance(c, _Frozen):
            return (_calibration_from_state, (dict(c.__dict__),))
        machine = Machine(c.machine())
        files = _machine_file_state(c)
        state = {
            "exit_code": c.exit_code,
            "names": list(c.names),
            "estimates": list(c.estimates),
            "sd": list(c.sd),
            "covariance": np.array(c.covariance),
            "warnings": list(c.warnings),
            "json": c.to_json(),
            "report_text": c.report(),
            "machine_json": machine.to_json(),
            "machine_source": machine.source,
            **files,
        }
        return (_calibration_from_state, (state,))

    def __repr__(self) -> str:
        j = json.loads(self.to_json())
        accuracy = (j.get("accuracy") or {}).get("rms_mm")
        return (
            f"Calibration(exit_code={self.exit_code}, data={j.get('data_file')!r}, "
            f"parameters={len(self.names)}, converged={j.get('converged')}, "
            f"adequate={j.get('adequate')}, rms_mm={accuracy})"
        )


def _calibration_from_state(state: Dict[str, Any]) -> Calibration:
    return Calibration(_Frozen(state))


class Diagnosis:
    """A diagnosis (``tricept diagnose``): ``exit_code`` (0 the final model
    explains the data, 3 it does not), ``verdict``, ``causes`` (the named
    effects), ``to_json()``, ``report()`` and ``write_machine(path,
    force=False)``. Pickles."""

    __slots__ = ("_d",)

    def __init__(self, compiled):
        self._d = compiled

    @property
    def exit_code(self) -> int:
        return self._d.exit_code

    def to_json(self) -> str:
        """The JSON ``tricept diagnose --json`` prints."""
        d = self._d
        return d.json if isinstance(d, _Frozen) else d.to_json()

    def report(self) -> str:
        """The report ``tricept diagnose`` prints."""
        d = self._d
        return d.report_text if isinstance(d, _Frozen) else d.report()

    @property
    def verdict(self) -> str:
        """``adequate``, ``explained``, ``partially-explained`` or ``unexplained``."""
        return json.loads(self.to_json())["verdict"]

    @property
    def causes(self) -> "list[str]":
        """The effects the diagnosis names, in its order."""
        return [c["effect"] for c in json.loads(self.to_json()).get("causes", [])]

    def write_machine(self, path: PathLike, force: bool = False) -> Optional[str]:
        """Writes the deployed machine file by the CLI's rule
        (:class:`UntrustedError` unless the final model explains the data,
        or ``force``); returns the warning of a forced write."""
        if isinstance(self._d, _Frozen):
            return _write_frozen(self._d, path, force)
        return self._d.write_machine(os.fspath(path), force)

    def __reduce__(self):
        d = self._d
        if isinstance(d, _Frozen):
            return (_diagnosis_from_state, (dict(d.__dict__),))
        # The machine file first: building it states the accuracy it
        # promises, which the JSON then carries (as `diagnose --json
        # --write-machine` prints it).
        state = _machine_file_state(d)
        state.update(exit_code=d.exit_code, json=d.to_json(), report_text=d.report())
        return (_diagnosis_from_state, (state,))

    def __repr__(self) -> str:
        return f"Diagnosis(exit_code={self.exit_code}, verdict={self.verdict!r}, causes={self.causes!r})"


def _diagnosis_from_state(state: Dict[str, Any]) -> Diagnosis:
    return Diagnosis(_Frozen(state))


class CheckResult:
    """A check against a calibration (``tricept check``): ``exit_code`` (0
    unchanged, 3 changed), ``verdict``, ``most_likely`` (the change, when
    changed), ``to_json()`` and ``report()``. Pickles."""

    __slots__ = ("_r",)

    def __init__(self, compiled):
        self._r = compiled

    @property
    def exit_code(self) -> int:
        return self._r.exit_code

    def to_json(self) -> str:
        """The JSON ``tricept check --json`` prints."""
        r = self._r
        return r.json if isinstance(r, _Frozen) else r.to_json()

    def report(self) -> str:
        """The report ``tricept check`` prints."""
        r = self._r
        return r.report_text if isinstance(r, _Frozen) else r.report()

    @property
    def verdict(self) -> str:
        """``unchanged``, ``noisier-than-stated``, ``changed``, ..."""
        return json.loads(self.to_json())["verdict"]

    @property
    def most_likely(self) -> Optional[str]:
        """The most likely change (``leg 2``, ...), ``None`` when unchanged."""
        j = json.loads(self.to_json())
        i = j.get("most_likely")
        return None if i is None else j["candidates"][i]["name"]

    def __reduce__(self):
        r = self._r
        if isinstance(r, _Frozen):
            return (_check_from_state, (dict(r.__dict__),))
        state = {"exit_code": r.exit_code, "json": r.to_json(), "report_text": r.report()}
        return (_check_from_state, (state,))

    def __repr__(self) -> str:
        return (
            f"CheckResult(exit_code={self.exit_code}, verdict={self.verdict!r}, "
            f"most_likely={self.most_likely!r})"
        )


def _check_from_state(state: Dict[str, Any]) -> CheckResult:
    return CheckResult(_Frozen(state))


def identify(data, machine=None, prior: Optional[PathLike] = None, **options) -> Calibration:
    """Identifies the machine's geometric errors from measured data, as
    ``tricept identify`` does.

    ``data``: a CSV path, a mapping of the CSV's column names
    (``q1, q2, q3, phi, theta, s`` and the optional ones) to 1-D arrays (a
    pandas DataFrame is one), or a list of CSV paths: campaigns of the same
    machine, pooled (the geometry shared, each campaign with its own sensor
    offsets; the ``campaigns`` entry of ``to_json()`` lists each one's
    offsets, chi-square and agreement), as ``--data`` given several times.
    ``machine``: a machine file or a :class:`Machine` (default: the
    built-in Table 1 machine).
    ``prior``: a batch's prior file (:func:`fleet`'s ``write_prior``): the
    calibration is then the maximum a posteriori estimate and its accuracy
    promise carries the prior's uncertainty, as ``--prior``.
    Options: ``params`` (``"paper15"`` or ``"full21"``), ``robust`` (reject
    gross readings, default True), ``tolerance_mm``, ``angle_noise_arcsec``,
    ``length_noise_um``, ``readings_per_pose``.

    Returns a :class:`Calibration`: ``exit_code`` (0, 3 or 4 as the CLI),
    ``estimates`` and ``sd`` (dicts, mm and rad), ``covariance`` (ndarray,
    in the order of ``names``), ``to_json()`` (the CLI's ``--json``),
    ``report()``, ``write_machine(path, force=False)`` and ``machine``.
    """
    extra: Dict[str, Any] = {}
    if isinstance(data, (list, tuple)):
        if not data:
            raise InputError("data: an empty list of campaigns")
        extra["campaigns"] = [os.fspath(p) for p in data[1:]]
        data = data[0]
    if prior is not None:
        extra["prior"] = os.fspath(prior)
    return Calibration(
        _tricept.identify(
            machine=_machine_arg(machine), **_data(data), **extra, **_int_options(options)
        )
    )


class Fleet:
    """A batch calibrated together (``tricept fleet``): ``exit_code`` (0,
    3 or 4 as the CLI), ``to_json()`` (the CLI's ``--json``), ``report()``
    and ``write_prior(path, force=False)``."""

    __slots__ = ("_f",)

    def __init__(self, compiled):
        self._f = compiled

    @property
    def exit_code(self) -> int:
        return self._f.exit_code

    def to_json(self) -> str:
        """The JSON ``tricept fleet --json`` prints."""
        return self._f.to_json()

    def report(self) -> str:
        """The report ``tricept fleet`` prints."""
        return self._f.report()

    def write_prior(self, path: PathLike, force: bool = False) -> Optional[str]:
        """Writes the batch's prior file (``--write-prior``) by the CLI's
        rule (:class:`UntrustedError` when the batch is not to be trusted,
        unless ``force``); returns why it was forced, if it was."""
        return self._f.write_prior(os.fspath(path), force)

    def __repr__(self) -> str:
        j = json.loads(self.to_json())
        return (
            f"Fleet(exit_code={self.exit_code}, machines={len(j.get('machines', []))}, "
            f"outliers={j.get('outliers')!r})"
        )


def fleet(data: Sequence[PathLike], machine=None, **options) -> Fleet:
    """Calibrates the machines of a batch together, one CSV path each, as
    ``tricept fleet`` does: the batch mean and its uncertainty, the
    machine-to-machine spread (REML), each machine with the batch as its
    prior, the machines that do not belong. ``machine``: the batch's
    nominal machine file or :class:`Machine`. Options: ``params``,
    ``tolerance_mm``, ``solver`` (``"schur"``, ``"sparse-cholesky"``,
    ``"sparse-qr"`` or ``"dense"``).

    Returns a :class:`Fleet`: ``exit_code`` (0, 3 or 4 as the CLI),
    ``to_json()`` (the CLI's ``--json``: ``batch_mean_mm``,
    ``batch_spread_mm``, ``machines``, ``outliers``, ``solver``, ...),
    ``report()`` and ``write_prior(path, force=False)``.
    """
    if isinstance(data, (str, os.PathLike)):
        raise InputError("data: a batch is a list of CSV paths, one per machine")
    return Fleet(
        _tricept.fleet(
            [os.fspath(p) for p in data], machine=_machine_arg(machine), **options
        )
    )


def diagnose(data, machine=None, **options) -> Diagnosis:
    """Does the geometric model explain the data, and if not, which effect
    does (``tricept diagnose``)? ``machine``: a machine file or a
    :class:`Machine`. Options: ``noise_from_data``, ``dictionary``,
    ``deploy_rule`` (``"expected-error"``, the default, or
    ``"confident"``, as ``--deploy-rule``). Returns a :class:`Diagnosis` with ``exit_code``,
    ``to_json()``, ``report()`` and ``write_machine(path, force=False)``."""
    return Diagnosis(_tricept.diagnose(machine=_machine_arg(machine), **_data(data), **options))


def check(machine, data, **options) -> CheckResult:
    """Has the machine changed since its calibration (``tricept check``)?
    ``machine`` is the calibrated machine file or :class:`Machine` (a
    calibration's ``machine`` from a data file). Options: ``alpha``,
    ``history``. Returns a :class:`CheckResult` with ``exit_code``,
    ``to_json()`` and ``report()``."""
    if machine is None:
        raise InputError("machine: check needs the calibrated machine (a file or a tricept.Machine)")
    if "history" in options and options["history"] is not None:
        options["history"] = os.fspath(options["history"])
    return CheckResult(_tricept.check(_machine_arg(machine), **_data(data), **options))


def simulate(
    machine=None,
    truth: str = "table2",
    effects: Union[str, Mapping, Sequence[Union[str, Mapping]]] = (),
    poses: str = "grid",
    seed: int = 1,
    **options,
) -> "dict[str, np.ndarray]":
    """Simulates a campaign on a machine with true errors (``tricept
    simulate``): ``machine`` (a file or a :class:`Machine`), ``truth``
    (``table2``, ``zero``, ``random:MAG_MM[,SEED]`` or a JSON file),
    ``effects`` (one effect or a list of them: JSON objects, dicts, or
    ``@FILE``, as ``--truth-effect``), ``poses`` (a ``--poses`` spec),
    ``seed``; options ``params``, ``both_directions``, ``noise_factor``,
    ``revisit`` (revisit the first N poses at the end, as ``--revisit``).
    Returns the CSV's columns as arrays (the file ``tricept simulate
    --out`` writes, read back)."""
    if isinstance(effects, (str, Mapping)):
        effects = [effects]
    options = _int_options({"seed": seed, **options})
    text = _tricept.simulate_csv(
        machine=_machine_arg(machine),
        truth=os.fspath(truth) if isinstance(truth, os.PathLike) else truth,
        effects=[e if isinstance(e, str) else json.dumps(e) for e in effects],
        poses=poses,
        **options,
    )
    lines = [l for l in text.splitlines() if l and not l.startswith("#")]
    header = lines[0].split(",")
    rows = [l.split(",") for l in lines[1:]]
    return {name: np.array([float(r[j]) for r in rows]) for j, name in enumerate(header)}


def _points(values, name: str) -> np.ndarray:
    """An (n, 3) C-contiguous float64 array (the same object when it is one)."""
    try:
        array = np.ascontiguousarray(values, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise InputError(f"{name}: not an array of numbers: {e}") from None
    if array.ndim == 1 and array.shape[0] == 3:
        array = array.reshape(1, 3)
    if array.ndim != 2:
        raise InputError(f"{name}: expected an (n, 3) array, got shape {array.shape}")
    return array


class Machine:
    """A machine: the built-in Table 1 machine, a description file, a
    description's JSON text, or a calibration's result (a calibrated one
    with its leg effects and compensation tables applied). Pickles (as its
    description's JSON, checked again when read back)."""

    __slots__ = ("_machine",)

    def __init__(self, machine):
        self._machine = machine

    @staticmethod
    def paper() -> "Machine":
        """The paper's Table 1 machine (the CLI's default machine)."""
        return Machine(_tricept.Machine.paper())

    @staticmethod
    def load(path: PathLike) -> "Machine":
        """A machine description file, loaded as every ``--machine`` of the
        CLI loads it: an edited calibrated file raises :class:`InputError`,
        a missing file :class:`FileNotFoundError`."""
        return Machine(_tricept.Machine.load(os.fspath(path)))

    @staticmethod
    def from_json(text: str, source: str = "<json>") -> "Machine":
        """A machine from a description's JSON text (what :meth:`to_json`
        gives), checked as a file is; ``source`` names it in messages."""
        return Machine(_tricept.Machine.from_json(text, source))

    def to_json(self) -> str:
        """The description as JSON text (with its calibration record)."""
        return self._machine.to_json()

    @property
    def source(self) -> str:
        """The file name, or ``the built-in Table 1 machine``."""
        return self._machine.source

    @property
    def name(self) -> str:
        """The description's ``name``."""
        return self._machine.name

    @property
    def calibration(self) -> Optional[str]:
        """The method of the calibration it holds (``identify``, ...), or ``None``."""
        return self._machine.calibration

    @property
    def warnings(self) -> "list[str]":
        """What loading it warned of, one line each."""
        return list(self._machine.warnings)

    def ik(self, points) -> np.ndarray:
        """Platform points ``(n, 3)`` (mm) to an ``(n, 6)`` array of
        ``q1, q2, q3`` (mm), ``phi, theta`` (rad), ``q4`` (mm)."""
        return self._machine.ik(_points(points, "ik: points"))

    def fk(self, q) -> np.ndarray:
        """Leg commands ``(n, 3)`` (mm) to an ``(n, 8)`` array of ``x, y, z``
        (mm), ``phi, theta`` (rad), ``q4`` (mm), condition, iterations."""
        return self._machine.fk(_points(q, "fk: q"))

    def tool_ik(self, points, axes) -> np.ndarray:
        """Tool tips and tool axes ``(n, 3)`` to an ``(n, 9)`` array of
        ``q1, q2, q3`` (mm), ``phi, theta`` (rad), ``q4`` (mm), ``h1, h2``
        (rad) and ``head_singular`` (0 or 1)."""
        return self._machine.tool_ik(
            _points(points, "tool_ik: points"), _points(axes, "tool_ik: axes")
        )

    def __reduce__(self):
        return (_machine_from_json, (self.to_json(), self.source))

    def __repr__(self) -> str:
        return repr(self._machine)


def _machine_from_json(text: str, source: str) -> Machine:
    return Machine(_tricept.Machine.from_json(text, source))


def report(
    machine: PathLike,
    out: PathLike,
    data: Optional[PathLike] = None,
    history: Optional[PathLike] = None,
    export: Optional[PathLike] = None,
) -> dict:
    """Writes the page of a calibrated machine file (``tricept report``):
    one self-contained HTML file at ``out``, with the calibration's
    campaign (``data``), its check history and its export folder when
    given. Returns the verdict as ``tricept report --json`` prints it
    (``out``, ``verdict``) with the CLI's ``exit_code`` (3 when the page
    says not to trust the machine). Inputs of another calibration raise
    :class:`InputError`."""

    def path(p):
        return None if p is None else os.fspath(p)

    return json.loads(
        _tricept.report(
            os.fspath(machine),
            os.fspath(out),
            data=path(data),
            history=path(history),
            export=path(export),
        )
    )
