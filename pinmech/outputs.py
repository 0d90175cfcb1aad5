"""Output files written whole or not at all.

Each output goes to a hidden temporary file next to its destination and is renamed over
it only when the run succeeds, so an existing file is never truncated or replaced by a
half-written one, and two runs writing the same path leave one complete file. When the
run fails or is interrupted, what was written is kept as `NAME.partial` (and the
destination is left as it was): a reader cannot take it for a complete result.

A destination that is a symbolic link is replaced by the file written, as `mv` would:
pinmech never writes through a link onto the file it points to (a link planted at an
output's name cannot make a run overwrite another file). A link to a folder on the way
to the destination is followed as usual.
"""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path
from typing import IO, Callable

from pinmech.exceptions import PinmechError
from pinmech.interrupts import SIGNALS

#: Figure formats `--plot` writes (matplotlib's, by suffix).
PLOT_FORMATS = ("png", "pdf", "svg")
PARTIAL_SUFFIX = ".partial"


class OutputFile:
    """A destination file, written through a temporary file in its folder.

    `open()` creates the temporary file (so a missing folder or a read-only one fails
    before any computing); `commit()` renames it over the destination; `abandon()` keeps
    what was written as `NAME.partial` (or removes it when empty) and returns that path.
    """

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        # the link itself, if the name is one, is replaced: never written through (see above)
        self.target = Path(os.path.realpath(self.path.parent)) / self.path.name
        self.temporary: Path | None = None
        self.stream: IO[str] | None = None
        self.direct = False  # a pipe or a device, written as the rows come

    def open(self, *, text: bool = True) -> IO[str] | None:
        """Create the temporary file; in text mode return it opened for writing. A pipe or a
        device (/dev/stdout) is written directly: it cannot be renamed over."""
        if text and _special(self.path):
            self.stream = open(self.path, "w", newline="", encoding="utf-8")  # noqa: SIM115
            self.direct = True
            return self.stream
        handle, name = tempfile.mkstemp(dir=self.target.parent, prefix=f".{self.target.name}.",
                                        suffix=f".tmp{self.target.suffix}")
        self.temporary = Path(name)
        os.chmod(handle, _mode(self.target))
        if not text:
            os.close(handle)
            return None
        self.stream = os.fdopen(handle, "w", newline="", encoding="utf-8")
        return self.stream

    def commit(self) -> Path:
        """Close the temporary file and rename it over the destination; the destination."""
        self._close()
        if self.temporary is not None:
            os.replace(self.temporary, self.target)
            self.temporary = None
        return self.path

    def abandon(self) -> Path | None:
        """Keep a non-empty temporary file as `NAME.partial` (returned); remove an empty one."""
        self._close()
        temporary, self.temporary = self.temporary, None
        if temporary is None or not temporary.exists():
            return None
        if temporary.stat().st_size == 0:
            temporary.unlink()
            return None
        partial = self.target.with_name(self.target.name + PARTIAL_SUFFIX)
        os.replace(temporary, partial)
        return partial

    def _close(self) -> None:
        if self.stream is not None:
            self.stream.close()
            self.stream = None


def _check_destination(option: str, path: Path) -> None:
    """A file can be made at `path`: it is not a folder, and its folder exists."""
    if path.is_dir():
        raise PinmechError(f"{option} {path} is a folder: give a file name")
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise PinmechError(f"{option} {path}: no such folder {folder}")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise PinmechError(f"{option} {path}: the folder {folder} is not writable")


def _special(path: Path) -> bool:
    """An existing file that is not a regular one (a pipe, /dev/stdout): written directly."""
    return path.exists() and not path.is_file() and not path.is_dir()


def _mode(path: Path) -> int:
    """Permissions of the new file: the existing file's, else those the umask allows."""
    try:
        if not path.is_symlink():  # a link's target's permissions are another file's
            return path.stat().st_mode & 0o777
    except OSError:
        pass
    umask = os.umask(0)
    os.umask(umask)
    return 0o666 & ~umask


def write_whole(path: str | Path, text: str) -> None:
    """Write a text file whole (through a temporary file renamed on success)."""
    output = OutputFile(path)
    stream = output.open()
    try:
        stream.write(text)
    except BaseException:
        output.abandon()
        raise
    output.commit()


def write_with(path: str | Path, write: Callable[[Path], object]) -> Path:
    """Write a file whole: `write(temporary)` fills a temporary file in its folder, renamed
    over `path` when it returns; on a failure what was written is kept as NAME.partial and
    `path` is left as it was (a figure, a Parquet table: writers that want a file name)."""
    output = OutputFile(path)
    output.open(text=False)
    try:
        write(output.temporary)
    except BaseException:
        output.abandon()
        raise
    return output.commit()


def beside(prefix: str | Path, ending: str) -> Path:
    """PREFIX + ending ("run.2" and ".csv" give "run.2.csv": a dot in the prefix is kept)."""
    return Path(f"{prefix}{ending}")


def plot_path(path: str, option: str = "--plot") -> Path:
    """The figure file `--plot PATH` writes: PATH itself, with ".png" added when it has no
    suffix. Checked before anything is computed.

    Raises:
        PinmechError: a suffix matplotlib does not write (only PNG, PDF and SVG).
    """
    target = Path(path)
    if target.is_dir() or target.name in ("", ".", ".."):
        raise PinmechError(f"{option} {path} is a folder: give a file name, e.g. fig.png")
    if _special(target):
        raise PinmechError(f"{option} {path} is not a regular file: give a file name, e.g. fig.png")
    suffix = target.suffix.lower().lstrip(".")
    if not suffix:
        return target.with_name(target.name.rstrip(".") + ".png")
    if suffix not in PLOT_FORMATS:
        raise PinmechError(f"{option} {path}: cannot draw a .{suffix} figure; use a name ending in "
                           f"{', '.join('.' + f for f in PLOT_FORMATS)}")
    return target


def check_distinct(outputs: dict[str, str | Path | None], inputs: dict[str, str | Path] | None = None) -> None:
    """Every output to its own file, and none over an input.

    Args:
        outputs: option -> path (None: not asked), e.g. {"--csv": "a.csv", "--json": None}.
        inputs: what the run reads, e.g. {"the scene": "four_bar.toml"}.

    Raises:
        PinmechError: two options name one file, or an option names an input.
    """
    seen: dict[str, str] = {}
    for option, path in outputs.items():
        if path is None:
            continue
        _check_destination(option, Path(path))
        key = os.path.realpath(path)
        if key in seen:
            raise PinmechError(f"{seen[key]} and {option} both name {path}: give each output its own file")
        seen[key] = option
    for what, path in (inputs or {}).items():
        key = os.path.realpath(path)
        if key in seen:
            raise PinmechError(f"{seen[key]} {path} would overwrite {what}: write the output elsewhere")


def check_prefix(option: str, prefix: str | Path, endings: list[str],
                 inputs: dict[str, str | Path] | None = None) -> None:
    """Before computing: each file `--out PREFIX` writes (PREFIX + ending) can be made, none
    is another's or an input (check_distinct), and PREFIX names no folder.

    Raises:
        PinmechError: naming the option, the file and what is wrong.
    """
    text = str(prefix)
    if not text or text.endswith(("/", os.sep)) or Path(text).is_dir() or Path(text).name in (".", ".."):
        raise PinmechError(f"{option} {text} is a folder: give a prefix of file names, e.g. {option} "
                           f"{Path(text) / 'run'}")
    check_distinct({f"{option} {text} ({ending})": beside(text, ending) for ending in endings}, inputs)


class Outputs:
    """Where streamed rows go (CSV, JSON lines, a figure), finished together: each file is
    written through a temporary file and renamed when every row is in (OutputFile); on a
    failure or a signal, what was written is kept as NAME.partial and the file named on
    the command line is left as it was. Each output says on stderr what was written."""

    def __init__(self) -> None:
        self.tables: list = []  # (table, OutputFile or None for stdout, what)
        self.figures: list = []  # (recorder, OutputFile)
        self.stdout: IO[str] | None = None  # a table on standard output, if any

    def table(self, kind: type, source: object, path: str | None, what: str | None) -> None:
        """A table (`kind(source, stream)`: CSV or JSON lines) to `path`, or to stdout."""
        output = OutputFile(path) if path else None
        stream = output.open() if output else sys.stdout
        if output is None:
            self.stdout = stream
        self.tables.append((kind(source, stream), output, what))

    def plot(self, recorder: object, path: Path | None) -> None:
        """A figure `recorder` (add rows, then save) drawn to `path` at the end; with no
        path, a recorder that only collects (the forces of a sweep, for their summary)."""
        output = OutputFile(path) if path is not None else None
        if output is not None:
            output.open(text=False)
        self.figures.append((recorder, output))

    def add(self, row: object) -> None:
        """One pose or path point to every output."""
        with SIGNALS.held():  # one row goes to every output or to none
            for table, _, _ in self.tables:
                table.add(row)
            for recorder, _ in self.figures:
                recorder.add(row)

    def __enter__(self) -> Outputs:  # noqa: PYI034
        return self

    def __exit__(self, kind, error, trace) -> None:
        if error is not None:
            self._abandon(error)
            return
        try:  # every row is in: the tables are complete, then the figures (which may still fail)
            with SIGNALS.held():  # all of them finished before a signal stops the run
                self._finish()
        except BaseException as exc:
            self._abandon(exc)
            raise

    def _finish(self) -> None:
        """Close the tables and rename them over their names, then draw and rename the figures."""
        counts = [table.close() for table, _, _ in self.tables]
        for (_, output, what), count in zip(self.tables, counts):
            if output:
                output.commit()
                said = f"{count} {what}" if what else "JSON lines"
                print(f"{said} written to {output.path}", file=sys.stderr)
        for recorder, output in self.figures:
            if output is None:
                continue
            try:
                recorder.save(output.temporary)
            except PinmechError as exc:  # named by the file the user asked for, not its temporary
                exc.args = (str(exc).replace(str(output.temporary), str(output.path)), *exc.args[1:])
                raise
            output.commit()
            print(f"figure written to {output.path}", file=sys.stderr)

    def _mark_stdout(self, error: BaseException) -> None:
        """Rows already sent to standard output (or a pipe) cannot be taken back: end them
        with a line that says the run stopped, so what reads them knows it is incomplete."""
        streams = [self.stdout] + [o.stream for _, o, _ in self.tables if o and o.direct]
        if isinstance(error, BrokenPipeError):
            return
        reason = " ".join(str(error).split()) or type(error).__name__
        for stream in [s for s in streams if s is not None]:
            try:
                stream.write(f"INCOMPLETE: pinmech stopped before the last row ({reason})\n")
                stream.flush()
            except (OSError, ValueError):  # closed or gone: nothing more can be said there
                pass

    def _abandon(self, error: BaseException) -> None:
        """Keep what was written as NAME.partial, and say so: in the error's own line (its
        `kept` attribute, which the CLI prints with it), else on stderr."""
        self._mark_stdout(error)
        kept = []
        for output in [o for _, o, _ in self.tables if o] + [o for _, o in self.figures if o]:
            partial = output.abandon()
            if partial:
                left = "left as it was" if output.path.exists() else "not written"
                kept.append(f"{partial} ({output.path} {left})")
        if not kept:
            return
        if isinstance(error, (PinmechError, KeyboardInterrupt, OSError)):
            error.kept = [*getattr(error, "kept", []), *kept]
        else:
            print(f"pinmech: incomplete output kept in {', '.join(kept)}", file=sys.stderr)
