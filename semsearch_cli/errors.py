"""User-facing errors: one clear paragraph, exit status 2, never a traceback."""


class ScenarioError(Exception):
    """Bad input from the user (a scenario file, a map, a command-line value).

    Parameters
    ----------
    file : str
        The file at fault (or ``"<command line>"``).
    field : str
        The field or key at fault (dotted path), or ``""`` when the whole file is at fault.
    message : str
        What is wrong and what was expected.
    """

    def __init__(self, file: str, field: str, message: str):
        self.file, self.field, self.message = str(file), field, message
        where = f"{self.file}" + (f", field '{field}'" if field else "")
        super().__init__(f"{where}: {message}")
