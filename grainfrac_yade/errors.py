"""User-facing errors: one clear line naming the file, the key and the fix; the exit status of a run without a
result."""

#: Exit status of a command whose run ended as a numerical failure (NaN or infinite numbers, contact statuses that
#: do not settle, a stalled clock): no result, and its summary.json says so (``numerical_failure: true``).  Neither
#: 0 (a result), 1 (an unexpected error, or a specimen that broke apart before its test) nor 2 (bad input), so that
#: a script can tell "the model gave no answer here" apart.
EXIT_NUMERICAL_FAILURE = 3


class GrainfracError(Exception):
    """An error caused by user input; the CLI prints it as one line, no traceback."""


class ParameterError(GrainfracError):
    """A parameter file or override is wrong.

    The message names the source (file path or ``--set``), the dotted key, the
    problem and the fix.
    """

    def __init__(self, source, key, problem, fix):
        self.source, self.key, self.problem, self.fix = source, key, problem, fix
        super().__init__(f"{source}: {key}: {problem}; fix: {fix}")


class NumericalFailure(ValueError):
    """A simulation produced NaN or infinite numbers (the DEM blew up) or stopped advancing.

    Not a user error and not a result: a creep run that meets it ends with
    ``numerical_failure: true`` in its summary, and the analysis lists it apart
    (never as a lifetime or a lower bound).  A ValueError, as the law's and the
    clocks' other checks on their arguments.
    """
