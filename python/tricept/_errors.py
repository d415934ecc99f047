"""The exceptions of the tricept package, defined in Python so that they
pickle (a worker process's error reaches its caller as itself) and are
named ``tricept.InputError`` and ``tricept.UntrustedError`` wherever they
show. The compiled half raises them; file-system failures are the
operating system's own ``OSError`` subclasses (``FileNotFoundError``,
``PermissionError``, ...)."""


class InputError(ValueError):
    """Bad input: a file's content, an array or an option; the message
    names the file, line and column, or the array row."""

    __module__ = "tricept"


class UntrustedError(RuntimeError):
    """A result that is not to be trusted was asked to be written (the
    CLI's refusal: exit code 3 or 4); ``force=True`` writes it, marked as
    forced. ``args`` are the message and the exit code."""

    __module__ = "tricept"

    def __init__(self, message: str, exit_code: int) -> None:
        super().__init__(message, exit_code)

    @property
    def exit_code(self) -> int:
        """The exit code of the refused result (3 or 4)."""
        return int(self.args[1])

    def __str__(self) -> str:
        return str(self.args[0])
