"""The ``tdm`` command. ``tdm info RECORDING`` summarises a recording.

``tdm run`` and ``tdm evaluate`` (DESIGN.md) arrive with the TDM issue.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from tdm import __version__
from tdm.errors import RecordingError
from tdm.io import read_manifest, read_ownship


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):
        raise RecordingError("command line", self.prog, message)


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``tdm`` console script."""
    parser = _Parser(prog="tdm", description="Target detection module: recordings in, detected targets out.")
    parser.add_argument("--version", action="version", version=f"tdm {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    info = sub.add_parser("info", help="summarise a recording directory")
    info.add_argument("recording", type=Path)
    try:
        args = parser.parse_args(argv)
        manifest = read_manifest(args.recording)
        nav = read_ownship(args.recording)
        print(f"{args.recording}: scenario {manifest.get('scenario')}, seed {manifest.get('seed')}, "
              f"{manifest.get('duration_s')} s, sensors {', '.join(manifest.get('sensors_rendered', [])) or 'none'}")
        print(f"  own ship: {nav['t'].shape[0]} navigation samples, {nav['t'][-1]:.1f} s")
        return 0
    except RecordingError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
