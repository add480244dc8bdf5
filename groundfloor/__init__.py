"""The ground floor under raysim and tdm: what both the renderer and the TDM need, owned by neither.

raysim writes recordings and tdm reads them; tdm never imports raysim (tests/tdm/test_io.py), so
whatever both must agree on lives here, once (docs/architecture.md "Floors"):

- :mod:`groundfloor.frames`: local ENU metres about an origin, body-to-world rotations, marine
  angles, sensor mounts;
- :mod:`groundfloor.units`: the knot and the nautical mile;
- :mod:`groundfloor.ais`: AIS navigational statuses and the reporting interval of a ship at anchor or moored;
- :mod:`groundfloor.hdl32e`: the Velodyne HDL-32E's facts (lasers, firing schedule, packet layout,
  the decoders' azimuths);
- :mod:`groundfloor.staging`: output directories that appear whole or not at all, write faults,
  SIGTERM as an interrupt;
- :mod:`groundfloor.recording`: the recording contract: file names, the sweep files' arrays and
  dtypes, and :class:`~groundfloor.recording.RecordingDescription`, a typed description of a
  recording (start time, duration, periods, ranges, mounts) built from its manifest and scenario.

groundfloor imports neither raysim nor tdm (checked by tests/tdm/test_io.py).
"""
