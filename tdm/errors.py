"""Bad recordings: one line naming the file, the place and what is wrong (exit code 2)."""

from __future__ import annotations


class RecordingError(Exception):
    """A recording file that cannot be read as its format says."""

    def __init__(self, file: str, where: str, what: str):
        self.file, self.where, self.what = str(file), str(where), " ".join(str(what).split())
        super().__init__(f"{self.file}: {self.where}: {self.what}")

    def __reduce__(self):  # raised in a worker process, re-raised in the parent
        return (type(self), (self.file, self.where, self.what))
