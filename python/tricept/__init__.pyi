"""Type stubs of the tricept package (lengths in mm, angles in rad)."""

import os
from typing import Any, Dict, List, Mapping, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

PathLike = Union[str, os.PathLike[str]]
Data = Union[PathLike, Mapping[str, npt.ArrayLike]]

class InputError(ValueError):
    """Bad input: the CLI's one-line message naming the file, line and column, or the row."""

class UntrustedError(RuntimeError):
    """A write refused by the CLI's rule (exit code 3 or 4); args: (message, exit_code)."""

class Machine:
    """A machine: the built-in Table 1 machine or a description file."""

    @staticmethod
    def paper() -> "Machine":
        """The paper's Table 1 machine (the CLI's default)."""
    @staticmethod
    def load(path: Union[str, os.PathLike[str]]) -> "Machine":
        """A machine file; an edited calibrated file raises InputError."""
    @property
    def source(self) -> str:
        """The file name, or the built-in machine."""
    def ik(self, points: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """(n, 3) platform points -> (n, 6): q1, q2, q3, phi, theta, q4."""
    def fk(self, q: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """(n, 3) leg commands -> (n, 8): x, y, z, phi, theta, q4, condition, iterations."""
    def tool_ik(self, points: npt.ArrayLike, axes: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """(n, 3) tool tips and axes -> (n, 9): q1, q2, q3, phi, theta, q4, h1, h2, head_singular."""

class Calibration:
    """A calibration (tricept identify)."""

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
    def to_json(self) -> str: ...
    def report(self) -> str: ...
    def write_machine(self, path: PathLike, force: bool = False) -> str: ...

class Diagnosis:
    """A diagnosis (tricept diagnose)."""

    @property
    def exit_code(self) -> int: ...
    def to_json(self) -> str: ...
    def report(self) -> str: ...
    def write_machine(self, path: PathLike, force: bool = False) -> Optional[str]: ...

class CheckResult:
    """A check against a calibration (tricept check)."""

    @property
    def exit_code(self) -> int: ...
    def to_json(self) -> str: ...
    def report(self) -> str: ...

class Fleet:
    """A batch calibrated together (tricept fleet)."""

    @property
    def exit_code(self) -> int: ...
    def to_json(self) -> str: ...
    def report(self) -> str: ...
    def write_prior(self, path: PathLike, force: bool = False) -> Optional[str]: ...

def fleet(
    data: Sequence[PathLike],
    machine: Optional[PathLike] = None,
    *,
    params: str = "paper15",
    tolerance_mm: Optional[float] = None,
    solver: str = "schur",
) -> Fleet:
    """The machines of a batch calibrated together (tricept fleet)."""

def identify(
    data: Union[Data, Sequence[PathLike]],
    machine: Optional[PathLike] = None,
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
    data: Data,
    machine: Optional[PathLike] = None,
    *,
    noise_from_data: bool = False,
    dictionary: bool = True,
    deploy_rule: str = "confident",
) -> Diagnosis:
    """Does the geometric model explain the data (tricept diagnose)?

    ``deploy_rule``: ``"confident"`` or ``"expected-error"`` (``--deploy-rule``).
    """

def check(
    machine: PathLike,
    data: Data,
    *,
    alpha: Optional[float] = None,
    history: Optional[PathLike] = None,
) -> CheckResult:
    """Has the machine changed since its calibration (tricept check)?"""

def simulate(
    machine: Optional[PathLike] = None,
    truth: str = "table2",
    effects: Sequence[Union[str, Mapping[str, Any]]] = (),
    poses: str = "grid",
    seed: int = 1,
    *,
    params: str = "paper15",
    both_directions: bool = False,
    noise_factor: float = 1.0,
) -> Dict[str, npt.NDArray[np.float64]]:
    """Simulates a campaign (tricept simulate --out), as column arrays."""
