"""User-facing errors: one clear line naming the file, the key and the fix."""


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
