"""Type stubs of the tricept package (lengths in mm, angles in rad)."""

import os
from typing import Union

import numpy as np
import numpy.typing as npt

class InputError(ValueError):
    """Bad input: the CLI's one-line message naming the file, line and column, or the row."""

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
