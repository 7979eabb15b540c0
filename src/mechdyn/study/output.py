"""The study table on disk: Parquet or CSV by suffix, written as the batches come.

Each finished batch is written at once as a part file in ``<output>.parts/`` (the same
format); :meth:`StudyOutput.finish` gathers the parts and any earlier table into the
output file, sorted by variant, and removes the parts.  A study that is interrupted
(or killed) keeps its parts; :meth:`StudyOutput.done` reads the output and the parts,
so that ``resume`` skips the variants already done.
"""

from __future__ import annotations

import shutil
from pathlib import Path

from ..errors import ModelError

__all__ = ["StudyOutput", "read_table", "write_table", "SUFFIXES"]

#: table formats by suffix
SUFFIXES = (".parquet", ".csv")


def _suffix(path: Path) -> str:
    s = path.suffix.lower()
    if s not in SUFFIXES:
        raise ModelError(f"study output {str(path)!r}: unknown table type {s or '(none)'!r}; "
                         f"use one of {', '.join(SUFFIXES)}")
    return s


def write_table(df, path: str | Path) -> Path:
    """Write a table as Parquet or CSV by the suffix of ``path``; returns the path.

    Raises
    ------
    ModelError
        A suffix other than ``.parquet`` or ``.csv``.
    """
    path = Path(path)
    if _suffix(path) == ".parquet":
        df.to_parquet(path, index=False)
    else:
        df.to_csv(path, index=False)
    return path


def read_table(path: str | Path):
    """A table written by :func:`write_table` (a ``message`` column reads as text)."""
    import pandas as pd

    path = Path(path)
    if _suffix(path) == ".parquet":
        return pd.read_parquet(path)
    df = pd.read_csv(path, keep_default_na=True)
    if "message" in df:
        df["message"] = df["message"].astype(object).where(df["message"].notna(), "").astype(str)
    return df


class StudyOutput:
    """The output of one study: batches appended as part files, gathered at the end.

    Parameters
    ----------
    path : str or Path
        ``.parquet`` or ``.csv``.

    Raises
    ------
    ModelError
        Another suffix.

    Examples
    --------
    >>> import pandas as pd, tempfile, pathlib
    >>> out = StudyOutput(pathlib.Path(tempfile.mkdtemp()) / "s.csv")
    >>> out.append([{"variant": 1, "status": "success", "message": ""}])
    >>> sorted(out.done())
    [1]
    >>> len(out.finish())
    1
    """

    def __init__(self, path: str | Path):
        self.path = Path(path)
        self.suffix = _suffix(self.path)
        self.parts = self.path.with_name(self.path.name + ".parts")
        self._count = 0

    def _part_files(self) -> list[Path]:
        return sorted(self.parts.glob(f"part-*{self.suffix}")) if self.parts.is_dir() else []

    def existing(self):
        """Everything written so far (the output file and the parts), or None."""
        import pandas as pd

        frames = [read_table(p) for p in self._part_files()]
        if self.path.is_file():
            frames.insert(0, read_table(self.path))
        frames = [f for f in frames if len(f)]
        if not frames:
            return None
        df = pd.concat(frames, ignore_index=True, sort=False)
        return df.drop_duplicates("variant", keep="last")

    def done(self) -> set[int]:
        """Ids of the variants already written."""
        df = self.existing()
        return set() if df is None else {int(v) for v in df["variant"]}

    def clear(self) -> None:
        """Remove the output and its parts (a fresh study)."""
        if self.parts.is_dir():
            shutil.rmtree(self.parts)
        if self.path.is_file():
            self.path.unlink()

    def append(self, rows: list[dict]) -> None:
        """Write one batch of rows as a new part file at once."""
        import pandas as pd

        if not rows:
            return
        self.parts.mkdir(parents=True, exist_ok=True)
        while True:
            self._count += 1
            part = self.parts / f"part-{self._count:06d}{self.suffix}"
            if not part.exists():
                break
        tmp = part.with_name("tmp-" + part.name)
        write_table(pd.DataFrame(rows), tmp)
        tmp.replace(part)  # a part is whole or absent, even when the study is killed

    def finish(self):
        """Gather everything written into the output file (sorted by variant), remove
        the parts; returns the table."""
        df = self.existing()
        if df is None:
            import pandas as pd

            df = pd.DataFrame({"variant": [], "status": [], "message": []})
        df = order_columns(df.sort_values("variant", kind="stable").reset_index(drop=True))
        tmp = self.path.with_name("tmp-" + self.path.name)
        write_table(df, tmp)
        tmp.replace(self.path)
        if self.parts.is_dir():
            shutil.rmtree(self.parts)
        return df


def order_columns(df):
    """``variant`` first, then the other columns as they are, ``status``, ``message``,
    ``evaluated`` and ``seconds`` last."""
    tail = [c for c in ("status", "message", "evaluated", "seconds") if c in df]
    head = ["variant"] if "variant" in df else []
    return df[head + [c for c in df if c not in head and c not in tail] + tail]
