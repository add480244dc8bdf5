"""Recordings the TDM tests run on: :func:`render_recording` and the session recordings
(``bos_recording``, ``crossing_recording``) live in tests/conftest.py, shared with tests/benchmarks.

The tdm package never imports raysim; its tests use raysim only to make recordings
with known truth, as a user would with the ``raysim render`` command.
"""

from __future__ import annotations

from tests.conftest import REPO, render_recording  # noqa: F401 (imported from here by the tdm tests)
