"""Files the user gives and files we write.

Reading: a user's file is checked before it is read (it exists, is a regular file, not a folder or
a device, is readable, not too large, and is UTF-8 text), so that every problem is one
:class:`~semsearch_cli.errors.ScenarioError` naming the file.

Writing atomically: every write goes to a temporary file beside its target, unique to the
writing process, and is then renamed over it, so a reader never sees half a file and two
processes writing the same file never share a temporary name."""

from __future__ import annotations

import hashlib
import os
import re
import stat
from pathlib import Path

from .errors import ScenarioError


def temp_path(path: Path) -> Path:
    """A temporary path beside ``path`` for an atomic write: hidden, unique to this process, and
    with the same suffix (libraries that pick a format from it still do)."""
    path = Path(path)
    return path.with_name(f".{path.stem}.{os.getpid()}.tmp{path.suffix}")


def atomic_text(path: Path, text: str) -> None:
    """Write a text file atomically (a reader never sees half of it); a failed write (a full
    disk) leaves neither half a file nor its temporary file behind."""
    tmp = temp_path(path)
    try:
        tmp.write_text(text)
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


MAX_TEXT_BYTES = 64 * 2**20  # a scenario, doors or log file larger than this is not one


def blame(path: Path, what: str, owner: str | None = None) -> tuple[str, str]:
    """(the file an error about ``path`` names, how its message names ``path``): the file itself,
    or, with ``owner`` (the scenario that named it), the owner, the message then saying which
    ``what`` it was."""
    return (owner, f"{what} {path}") if owner else (str(path), what)


def user_file(path: str | Path, what: str, owner: str | None = None, field: str = "") -> Path:
    """``path`` when it is an existing regular file that can be read, else a
    :class:`ScenarioError` that names it: missing, a folder, a device or a pipe (``/dev/zero``),
    or unreadable. The error is the file's own, or, with ``owner`` (the scenario that named it),
    the owner's ``field``."""
    path = Path(path)
    file, where = blame(path, what, owner)
    try:
        st = path.stat()
    except (FileNotFoundError, NotADirectoryError):
        raise ScenarioError(file, field, f"{where} not found" + (f" (looked for {path.resolve()}; a scenario's relative "
                                                                 "paths are read from the folder the scenario is in)" if owner else
                                                                 f" (looked for {path.resolve()})" if not path.is_absolute()
                                                                 else "")) from None
    except OSError as exc:
        raise ScenarioError(file, field, f"{where} cannot be read ({exc.strerror})") from None
    if stat.S_ISDIR(st.st_mode):
        raise ScenarioError(file, field, f"{where} is a folder, not a file")
    if not stat.S_ISREG(st.st_mode):
        raise ScenarioError(file, field, f"{where} is not a regular file (a device, a pipe or a socket)")
    if not os.access(path, os.R_OK):
        raise ScenarioError(file, field, f"{where} cannot be read (permission denied)")
    return path


def read_user_text(path: str | Path, what: str, owner: str | None = None, field: str = "",
                   limit: int = MAX_TEXT_BYTES) -> str:
    """The text of a user's file (UTF-8, a byte-order mark allowed), or a :class:`ScenarioError`
    naming it (see :func:`user_file`): too large, or not UTF-8 (UTF-16, Latin-1, binary), with
    the offending byte."""
    path = user_file(path, what, owner, field)
    file, where = blame(path, what, owner)
    size = path.stat().st_size
    if size > limit:
        raise ScenarioError(file, field, f"{where} is {size / 2**20:.0f} MB; a text file over {limit // 2**20} MB is not one semsearch reads")
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise ScenarioError(file, field, f"{where} cannot be read ({exc.strerror})") from None
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        kind = "UTF-16 text" if data[:2] in (b"\xff\xfe", b"\xfe\xff") else "not UTF-8 text"
        if b"\x00" in data[:1024] and kind != "UTF-16 text":
            kind = "binary, not text"
        raise ScenarioError(file, field, f"{where} is {kind} (byte 0x{data[exc.start]:02x} at offset {exc.start}); "
                            "save it as UTF-8") from None


def output_folder(out: str | Path, flag: str = "--out") -> Path:
    """The output folder ``out``, created if needed, or a :class:`ScenarioError` for ``flag`` that
    says why it cannot be: empty, a file, under a file, or on a file system that refuses it
    (read-only, no permission, /proc)."""
    if str(out).strip() == "":
        raise ScenarioError("<command line>", flag, "an empty folder name; give a folder (it is created if needed)")
    out = Path(out)
    for p in (out, *out.parents):
        if p.exists() and not p.is_dir():
            what = "is a file" if p == out else f"lies under {p}, which is a file"
            raise ScenarioError("<command line>", flag, f"{out} {what}; give a folder (it is created if needed)")
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ScenarioError("<command line>", flag, f"cannot create the folder {out}: {exc.strerror or exc}") from None
    if not os.access(out, os.W_OK | os.X_OK):
        raise ScenarioError("<command line>", flag, f"cannot write into {out}: permission denied")
    return out


def check_outputs(folder: Path, files: tuple[str, ...] = (), folders: tuple[str, ...] = (), flag: str = "--out") -> None:
    """Before anything is written into ``folder``: each of ``files`` that exists there is a file,
    each of ``folders`` a folder; a :class:`ScenarioError` for ``flag`` naming the first that is
    not (a command would otherwise stop half-way, its runs done and its report not written)."""
    for names, want_dir in ((files, False), (folders, True)):
        for name in names:
            p = Path(folder) / name
            if (p.exists() or p.is_symlink()) and (p.is_dir() != want_dir or not (p.is_dir() or p.is_file())):
                what = "a folder" if p.is_dir() else "a file" if p.is_file() else "neither a file nor a folder"
                raise ScenarioError("<command line>", flag, f"{p} is {what}, where semsearch writes its "
                                    f"{'folder' if want_dir else 'file'} {name}; move it away, or write into another "
                                    "folder")


def output_file(path: str | Path, flag: str, suffixes: tuple[str, ...]) -> Path:
    """``path`` for a file to write, its folder created: refused (a :class:`ScenarioError` for
    ``flag``) when empty, a folder, of a type not among ``suffixes``, or in a folder that cannot
    be made or written (see :func:`output_folder`)."""
    if str(path).strip() == "":
        raise ScenarioError("<command line>", flag, "an empty file name")
    path = Path(path)
    if path.is_dir():
        raise ScenarioError("<command line>", flag, f"{path} is a folder; give a file name ending in {', '.join(suffixes)}")
    if path.suffix.lower() not in suffixes:
        raise ScenarioError("<command line>", flag, f"cannot write {path.suffix or 'a file without an extension'}; "
                            f"give a file name ending in {', '.join(suffixes)}")
    output_folder(path.parent, flag)
    probe = temp_path(path)
    try:  # a folder that exists but takes no files (/proc, a read-only mount)
        probe.open("w").close()
        probe.unlink()
    except OSError as exc:
        raise ScenarioError("<command line>", flag, f"cannot write files in {path.parent}: "
                            f"{exc.strerror or exc}") from None
    return path


MAX_COMPONENT = 120  # characters of a name made from a value, before its hash


def safe_chars(text, keep: str = "") -> str:
    """``text`` with every character but letters, digits, ``._+-`` (and those of ``keep``)
    replaced by ``_``: one file-name component, whatever a label or value holds (a KTH room's
    second door is the goal ``2512/2``)."""
    return re.sub(rf"[^A-Za-z0-9._+\-{re.escape(keep)}]", "_", str(text))


def component(text) -> str:
    """``text`` (a value, a case name: anything a user wrote) as one file-name component that
    stays where it is put: characters other than letters, digits and ``._+=-`` become ``_``,
    leading dots go (no ``..``, no hidden file), and a name that had to change, or is long, gets a
    short hash of the original, so two values never share a folder."""
    text = str(text)
    safe = safe_chars(text, "=").lstrip(".") or "_"
    if safe == text and len(safe) <= MAX_COMPONENT:
        return safe
    return f"{safe[:MAX_COMPONENT]}-{hashlib.sha1(text.encode()).hexdigest()[:8]}"


def inside(folder: Path, name, flag: str = "--out") -> Path:
    """``folder / component(name)``, checked to lie inside ``folder`` (a :class:`ScenarioError`
    for ``flag`` otherwise: every file a command writes lies inside its output folder)."""
    path = Path(folder) / component(name)
    if path.resolve().parent != Path(folder).resolve():
        raise ScenarioError("<command line>", flag, f"{name!r} would write outside {folder}")
    return path


def cache_dir() -> Path:
    """Where semsearch keeps what it makes once per machine (generated bench splits, fetched
    floors, the llm planner's request slots): ``$SEMSEARCH_CACHE``, else
    ``$XDG_CACHE_HOME/semsearch``, else ``~/.cache/semsearch``."""
    if os.environ.get("SEMSEARCH_CACHE"):
        return Path(os.environ["SEMSEARCH_CACHE"])
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "semsearch"


def sha256_file(path: Path) -> str:
    """A file's SHA-256, read a megabyte at a time (a model's weights, a fetched floor's source)."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()
