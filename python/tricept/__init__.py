"""tricept: self-calibration of the Tricept parallel kinematic machine.

Machines and batch kinematics on numpy arrays, computed by the same Rust
library as the ``tricept`` command line (lengths in mm, angles in rad)::

    import numpy as np, tricept
    m = tricept.Machine.paper()
    q = m.ik(np.array([[0.0, 0.0, 750.0]]))   # (1, 6): q1, q2, q3, phi, theta, q4

Arrays are read in place when they are C-contiguous float64 (anything else
is converted once); the points are solved in parallel with the GIL released.
Bad input raises :class:`InputError`, a :class:`ValueError`.

The workflows are the CLI's, through the same library calls:
:func:`identify` (``tricept identify``), :func:`diagnose`, :func:`check` and
:func:`simulate`. Data are a CSV path or a mapping of the CSV's column names
to 1-D arrays (a pandas DataFrame is one); results carry the CLI's exit
code and ``to_json()`` is the CLI's ``--json``.
"""

import json
import os
from typing import Mapping, Optional, Sequence, Union

import numpy as np

from . import _tricept
from ._tricept import InputError, UntrustedError

__all__ = [
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
]

Diagnosis = _tricept.Diagnosis
CheckResult = _tricept.CheckResult
Fleet = _tricept.Fleet

PathLike = Union[str, os.PathLike]


def _data(data) -> dict:
    """The data argument as keyword arguments of the compiled workflows:
    a path, or CSV text written from a mapping of column arrays with
    shortest round-trip numbers (the same float64 bits)."""
    if isinstance(data, (str, os.PathLike)):
        return {"path": os.fspath(data)}
    try:
        names = [str(k) for k in data.keys()]
    except AttributeError:
        raise InputError("data: expected a CSV path or a mapping of column names to arrays") from None
    columns = []
    for k in names:
        c = np.asarray(data[k])
        if c.ndim != 1:
            raise InputError(f"data: column `{k}` is not one-dimensional (shape {c.shape})")
        columns.append(c)
    n = {len(c) for c in columns}
    if len(n) > 1:
        raise InputError(f"data: the columns have different lengths {sorted(n)}")
    lines = [",".join(names)]
    for row in zip(*columns):
        lines.append(",".join(_cell(v) for v in row))
    return {"csv_text": "\n".join(lines) + "\n"}


def _cell(v) -> str:
    if isinstance(v, (float, np.floating)):
        return repr(float(v))
    if isinstance(v, (bool, np.bool_)):
        return "1" if v else "0"
    return str(v)


class Calibration:
    """A calibration (``tricept identify``): ``exit_code`` (0 trusted, 3
    the model does not explain the data or the campaign is too small, 4 not
    converged), ``estimates`` and ``sd`` by parameter name (mm, rad; an sd
    of ``None`` is a held parameter), ``covariance`` (in the order of
    ``names``), ``warnings``, ``to_json()``, ``report()`` and
    ``write_machine(path, force=False)``."""

    __slots__ = ("_c",)

    def __init__(self, compiled: "_tricept.Calibration"):
        self._c = compiled

    @property
    def exit_code(self) -> int:
        return self._c.exit_code

    @property
    def names(self) -> "list[str]":
        return self._c.names

    @property
    def estimates(self) -> "dict[str, float]":
        return dict(self._c.estimates)

    @property
    def sd(self) -> "dict[str, Optional[float]]":
        return dict(self._c.sd)

    @property
    def covariance(self) -> np.ndarray:
        return self._c.covariance

    @property
    def warnings(self) -> "list[str]":
        return self._c.warnings

    def to_json(self) -> str:
        """The JSON ``tricept identify --json`` prints."""
        return self._c.to_json()

    def report(self) -> str:
        """The report ``tricept identify`` prints."""
        return self._c.report()

    def write_machine(self, path: PathLike, force: bool = False) -> str:
        """Writes the calibrated machine file by the CLI's rule: a result
        that is not to be trusted raises :class:`UntrustedError` unless
        ``force``; a calibration from arrays cannot record its data file
        and raises :class:`InputError`."""
        return self._c.write_machine(os.fspath(path), force)

    def __repr__(self) -> str:
        return f"Calibration(exit_code={self.exit_code}, parameters={len(self.names)})"


def identify(
    data, machine: Optional[PathLike] = None, prior: Optional[PathLike] = None, **options
) -> "Calibration":
    """Identifies the machine's geometric errors from measured data, as
    ``tricept identify`` does.

    ``data``: a CSV path, a mapping of the CSV's column names
    (``q1, q2, q3, phi, theta, s`` and the optional ones) to 1-D arrays, or
    a list of CSV paths: campaigns of the same machine, pooled (the
    geometry shared, each campaign with its own sensor offsets; the
    ``campaigns`` entry of ``to_json()`` lists each one's offsets,
    chi-square and agreement), as ``--data`` given several times.
    ``machine``: a machine file (default: the built-in Table 1 machine).
    ``prior``: a batch's prior file (:func:`fleet`'s ``write_prior``): the
    calibration is then the maximum a posteriori estimate and its accuracy
    promise carries the prior's uncertainty, as ``--prior``.
    Options: ``params`` (``"paper15"`` or ``"full21"``), ``robust`` (reject
    gross readings, default True), ``tolerance_mm``, ``angle_noise_arcsec``,
    ``length_noise_um``, ``readings_per_pose``.

    Returns a :class:`Calibration`: ``exit_code`` (0, 3 or 4 as the CLI),
    ``estimates`` and ``sd`` (dicts, mm and rad), ``covariance`` (ndarray,
    in the order of ``names``), ``to_json()`` (the CLI's ``--json``),
    ``report()`` and ``write_machine(path, force=False)``.
    """
    extra = {}
    if isinstance(data, (list, tuple)):
        if not data:
            raise InputError("data: an empty list of campaigns")
        extra["campaigns"] = [os.fspath(p) for p in data[1:]]
        data = data[0]
    if prior is not None:
        extra["prior"] = os.fspath(prior)
    return Calibration(
        _tricept.identify(
            machine=None if machine is None else os.fspath(machine),
            **_data(data),
            **extra,
            **options,
        )
    )


def fleet(data: Sequence[PathLike], machine: Optional[PathLike] = None, **options) -> "Fleet":
    """Calibrates the machines of a batch together, one CSV path each, as
    ``tricept fleet`` does: the batch mean and its uncertainty, the
    machine-to-machine spread (REML), each machine with the batch as its
    prior, the machines that do not belong. ``machine``: the batch's
    nominal machine file. Options: ``params``, ``tolerance_mm``, ``solver``
    (``"schur"``, ``"sparse-cholesky"``, ``"sparse-qr"`` or ``"dense"``).

    Returns a :class:`Fleet`: ``exit_code`` (0, 3 or 4 as the CLI),
    ``to_json()`` (the CLI's ``--json``: ``batch_mean_mm``,
    ``batch_spread_mm``, ``machines``, ``outliers``, ``solver``, ...),
    ``report()`` and ``write_prior(path, force=False)``.
    """
    if isinstance(data, (str, os.PathLike)):
        raise InputError("data: a batch is a list of CSV paths, one per machine")
    return _tricept.fleet(
        [os.fspath(p) for p in data],
        machine=None if machine is None else os.fspath(machine),
        **options,
    )


def diagnose(data, machine: Optional[PathLike] = None, **options) -> "Diagnosis":
    """Does the geometric model explain the data, and if not, which effect
    does (``tricept diagnose``)? Options: ``noise_from_data``,
    ``dictionary``, ``deploy_rule`` (``"confident"`` or
    ``"expected-error"``, as ``--deploy-rule``). Returns a :class:`Diagnosis` with ``exit_code``,
    ``to_json()``, ``report()`` and ``write_machine(path, force=False)``."""
    return _tricept.diagnose(
        machine=None if machine is None else os.fspath(machine), **_data(data), **options
    )


def check(machine: PathLike, data, **options) -> "CheckResult":
    """Has the machine changed since its calibration (``tricept check``)?
    ``machine`` is the calibrated machine file. Options: ``alpha``,
    ``history``. Returns a :class:`CheckResult` with ``exit_code``,
    ``to_json()`` and ``report()``."""
    return _tricept.check(os.fspath(machine), **_data(data), **options)


def simulate(
    machine: Optional[PathLike] = None,
    truth: str = "table2",
    effects: Sequence[Union[str, Mapping]] = (),
    poses: str = "grid",
    seed: int = 1,
    **options,
) -> "dict[str, np.ndarray]":
    """Simulates a campaign on a machine with true errors (``tricept
    simulate``): ``truth`` (``table2``, ``zero``, ``random:MAG_MM[,SEED]`` or
    a JSON file), ``effects`` (JSON objects or dicts, as ``--truth-effect``),
    ``poses`` (a ``--poses`` spec), ``seed``; options ``params``,
    ``both_directions``, ``noise_factor``. Returns the CSV's columns as
    arrays (the file ``tricept simulate --out`` writes, read back)."""
    text = _tricept.simulate_csv(
        machine=None if machine is None else os.fspath(machine),
        truth=truth,
        effects=[e if isinstance(e, str) else json.dumps(e) for e in effects],
        poses=poses,
        seed=seed,
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
    """A machine: the built-in Table 1 machine or a description file (a
    calibrated one with its leg effects and compensation tables applied)."""

    __slots__ = ("_machine",)

    def __init__(self, machine: "_tricept.Machine"):
        self._machine = machine

    @staticmethod
    def paper() -> "Machine":
        """The paper's Table 1 machine (the CLI's default machine)."""
        return Machine(_tricept.Machine.paper())

    @staticmethod
    def load(path: Union[str, os.PathLike]) -> "Machine":
        """A machine description file, loaded as every ``--machine`` of the
        CLI loads it: an edited calibrated file raises :class:`InputError`."""
        return Machine(_tricept.Machine.load(os.fspath(path)))

    @property
    def source(self) -> str:
        """The file name, or ``the built-in Table 1 machine``."""
        return self._machine.source

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

    def __repr__(self) -> str:
        return f"Machine({self.source!r})"
