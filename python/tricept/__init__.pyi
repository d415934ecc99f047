"""Type stubs of the tricept package (lengths in mm, angles in rad)."""

import os
from typing import Any, Dict, Iterable, List, Mapping, Optional, Protocol, Sequence, Union

import numpy as np
import numpy.typing as npt

from ._errors import InputError as InputError
from ._errors import UntrustedError as UntrustedError

__version__: str

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

PathLike = Union[str, os.PathLike[str]]

class _Columns(Protocol):
    """Anything with named columns: a mapping, or a pandas DataFrame."""

    def keys(self) -> Iterable[Any]: ...
    def __getitem__(self, key: Any, /) -> Any: ...

_Data = Union[PathLike, Mapping[str, npt.ArrayLike], _Columns]
_MachineArg = Union[PathLike, "Machine"]

class Machine:
    """A machine: the built-in Table 1 machine, a description file, a description's JSON, or a calibration's."""

    def __init__(self, machine: Any) -> None: ...
    @staticmethod
    def paper() -> "Machine":
        """The paper's Table 1 machine (the CLI's default)."""
    @staticmethod
    def load(path: PathLike) -> "Machine":
        """A machine file; an edited calibrated file raises InputError, a missing one FileNotFoundError."""
    @staticmethod
    def from_json(text: str, source: str = "<json>") -> "Machine":
        """A machine from a description's JSON text, checked as a file is."""
    def to_json(self) -> str:
        """The description as JSON text."""
    @property
    def source(self) -> str:
        """The file name, or the built-in machine."""
    @property
    def name(self) -> str: ...
    @property
    def calibration(self) -> Optional[str]: ...
    @property
    def warnings(self) -> List[str]: ...
    def ik(self, points: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """(n, 3) platform points -> (n, 6): q1, q2, q3, phi, theta, q4."""
    def fk(self, q: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """(n, 3) leg commands -> (n, 8): x, y, z, phi, theta, q4, condition, iterations."""
    def tool_ik(self, points: npt.ArrayLike, axes: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """(n, 3) tool tips and axes -> (n, 9): q1, q2, q3, phi, theta, q4, h1, h2, head_singular."""

class Calibration:
    """A calibration (tricept identify)."""

    def __init__(self, compiled: Any) -> None: ...
    @property
    def exit_code(self) -> int: ...
    @property
    def names(self) -> List[str]: ...
    @property
    def estimates(self) -> Dict[str, float]: ...
    @property
    def sd(self) -> Dict[str, Optional[float]]: ...
    @property
    def covariance(self) -> npt.NDArray[np.float64]: ...
    @property
    def warnings(self) -> List[str]: ...
    @property
    def machine(self) -> Machine: ...
    def to_json(self) -> str: ...
    def report(self) -> str: ...
    def write_machine(self, path: PathLike, force: bool = False) -> str: ...

class Diagnosis:
    """A diagnosis (tricept diagnose)."""

    def __init__(self, compiled: Any) -> None: ...
    @property
    def exit_code(self) -> int: ...
    @property
    def verdict(self) -> str: ...
    @property
    def causes(self) -> List[str]: ...
    def to_json(self) -> str: ...
    def report(self) -> str: ...
    def write_machine(self, path: PathLike, force: bool = False) -> Optional[str]: ...

class CheckResult:
    """A check against a calibration (tricept check)."""

    def __init__(self, compiled: Any) -> None: ...
    @property
    def exit_code(self) -> int: ...
    @property
    def verdict(self) -> str: ...
    @property
    def most_likely(self) -> Optional[str]: ...
    def to_json(self) -> str: ...
    def report(self) -> str: ...

class Fleet:
    """A batch calibrated together (tricept fleet)."""

    def __init__(self, compiled: Any) -> None: ...
    @property
    def exit_code(self) -> int: ...
    def to_json(self) -> str: ...
    def report(self) -> str: ...
    def write_prior(self, path: PathLike, force: bool = False) -> Optional[str]: ...

def fleet(
    data: Sequence[PathLike],
    machine: Optional[_MachineArg] = None,
    *,
    params: str = "paper15",
    tolerance_mm: Optional[float] = None,
    solver: str = "schur",
) -> Fleet:
    """The machines of a batch calibrated together (tricept fleet)."""

def identify(
    data: Union[_Data, Sequence[PathLike]],
    machine: Optional[_MachineArg] = None,
    prior: Optional[PathLike] = None,
    *,
    params: str = "paper15",
    robust: bool = True,
    tolerance_mm: Optional[float] = None,
    angle_noise_arcsec: Optional[float] = None,
    length_noise_um: Optional[float] = None,
    readings_per_pose: Optional[int] = None,
) -> Calibration:
    """Identifies the geometric errors (tricept identify)."""

def diagnose(
    data: _Data,
    machine: Optional[_MachineArg] = None,
    *,
    noise_from_data: bool = False,
    dictionary: bool = True,
    deploy_rule: str = "expected-error",
) -> Diagnosis:
    """Does the geometric model explain the data (tricept diagnose)?

    ``deploy_rule``: ``"expected-error"`` (the default) or ``"confident"`` (``--deploy-rule``).
    """

def check(
    machine: _MachineArg,
    data: _Data,
    *,
    alpha: Optional[float] = None,
    history: Optional[PathLike] = None,
) -> CheckResult:
    """Has the machine changed since its calibration (tricept check)?"""

def simulate(
    machine: Optional[_MachineArg] = None,
    truth: Union[str, os.PathLike[str]] = "table2",
    effects: Union[str, Mapping[str, Any], Sequence[Union[str, Mapping[str, Any]]]] = (),
    poses: str = "grid",
    seed: int = 1,
    *,
    params: str = "paper15",
    both_directions: bool = False,
    noise_factor: float = 1.0,
    revisit: int = 0,
) -> Dict[str, npt.NDArray[np.float64]]:
    """Simulates a campaign (tricept simulate --out), as column arrays."""

def report(
    machine: PathLike,
    out: PathLike,
    data: Optional[PathLike] = None,
    history: Optional[PathLike] = None,
    export: Optional[PathLike] = None,
) -> Dict[str, Any]:
    """Writes the page of a calibrated machine (tricept report); its verdict."""
