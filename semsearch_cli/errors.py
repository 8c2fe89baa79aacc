"""User-facing errors: one clear paragraph, exit status 2, never a traceback; and the faults that
stop a batch (one paragraph too, with the status they end with)."""

import difflib
import errno

DISK_FULL = (errno.ENOSPC, errno.EDQUOT)  # what a write on a full disk (or quota) raises


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


class MissingExtra(ScenarioError):
    """An optional package that is not installed (or too old) for what was asked: one line,
    ``semsearch export needs the ros extra: pip install 'semsearch[ros]'``, exit status 2.

    Parameters
    ----------
    what : str
        What needs it (``"semsearch export"``, ``"the llm planner"``).
    extra : str
        The pyproject extra that installs it.
    detail : str
        Why, when more than absence (an import error's text).
    """

    def __init__(self, what: str, extra: str, detail: str = ""):
        self.extra = extra
        message = f"{what} needs the {extra} extra: pip install 'semsearch[{extra}]'" + (f" ({detail})" if detail else "")
        super().__init__("<install>", "", message)
        self.args = (message,)

    def __str__(self) -> str:
        return self.message


class BatchStopped(Exception):
    """A batch stopped by a fault, not by bad input: a worker process died, the disk filled, the
    batch was told to stop (SIGTERM). The rows finished are kept; the same command resumes.

    Parameters
    ----------
    what : str
        What happened, in a sentence.
    status : int
        The exit status the command ends with (1; 143 for SIGTERM).
    """

    def __init__(self, what: str, status: int = 1):
        self.what, self.status = what, status
        super().__init__(what)


class PlannerError(Exception):
    """A planner's decision the simulator cannot follow (off the map, not a free cell, not a
    number): the run is recorded with outcome ``error`` and this message, naming the planner and
    the value."""


class Unavailable(Exception):
    """A run that failed for a cause outside it: a package its planner needs is not installed, a
    service it talks to (a language model's endpoint) did not answer. The run is recorded with
    outcome ``error`` and a message that starts with :data:`UNAVAILABLE`; such a row is never
    taken as done: the same command runs it again (its row kept in ``runs.superseded.csv``). A run
    that failed on its own (a planner's exception, :class:`PlannerError`) stays done."""


UNAVAILABLE = "unavailable: "  # how the message of a run that failed for a cause outside it starts


class BudgetSpent(PlannerError):
    """A planner's own budget for a run (a language model's calls or tokens) is spent: the run
    ends with outcome ``budget`` and this message, as when the scenario's distance budget is."""


class RunTimeout(BaseException):
    """A run past its wall-clock limit (``experiment.run_time_limit``); a BaseException, so that a
    planner's ``except Exception`` cannot swallow it."""


class Terminated(BaseException):
    """SIGTERM, raised in the main thread (like KeyboardInterrupt for SIGINT), so that a batch
    told to stop stops its workers and says what it kept."""


def did_you_mean(name: str, valid) -> str:
    """`` (did you mean 'alpha'?)`` for the valid names nearest a mistyped ``name`` (difflib's
    similarity ratio at least 0.6, and within 0.1 of the nearest's; at most three), or ``""``
    when none is near."""
    scored = sorted(((difflib.SequenceMatcher(None, str(name), str(v)).ratio(), str(v)) for v in valid), reverse=True)
    near = [v for r, v in scored if r >= 0.6 and r >= scored[0][0] - 0.1][:3]
    if not near:
        return ""
    return " (did you mean " + " or ".join(repr(n) for n in near) + "?)"
