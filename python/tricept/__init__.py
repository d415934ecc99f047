"""tricept: self-calibration of the Tricept parallel kinematic machine.

Machines and batch kinematics on numpy arrays, computed by the same Rust
library as the ``tricept`` command line (lengths in mm, angles in rad)::

    import numpy as np, tricept
    m = tricept.Machine.paper()
    q = m.ik(np.array([[0.0, 0.0, 750.0]]))   # (1, 6): q1, q2, q3, phi, theta, q4

Arrays are read in place when they are C-contiguous float64 (anything else
is converted once); the points are solved in parallel with the GIL released.
Bad input raises :class:`InputError`, a :class:`ValueError`.
"""

import os
from typing import Union

import numpy as np

from . import _tricept
from ._tricept import InputError

__all__ = ["InputError", "Machine"]


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
