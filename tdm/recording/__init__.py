"""Reading a recording: one contract, file by file (docs/formats.md, "Reading a recording: warnings and errors").

Every file the TDM reads goes through a module of this package, which checks it against the
recording's format (its names, sweep arrays and dtypes: :mod:`groundfloor.recording`, the contract
raysim writes by) and decides, for each defect, between

* a *warning*: what a real logger leaves (a cut last line, a sweep file cut short by a crash, a
  missing sweep number, a truncated PCAP record, a packet out of time, a bad NMEA line), counted
  in a :class:`tdm.detections.ReadStats` under a stable key and skipped; and
* an *error*: anything else, a :class:`tdm.errors.RecordingError` naming the file, the place and
  what is wrong, which the ``tdm`` command prints as one line and exits with code 2, nothing written.

No size is taken from a file's numbers without a bound (durations, rates, counts, array headers).

Modules, one job each:

- :mod:`~tdm.recording.values`: single values (finite, bounded numbers, mappings, strings);
- :mod:`~tdm.recording.files`: a readable regular file is there (not a directory, a loop, ...);
- :mod:`~tdm.recording.manifest`: ``manifest.json``;
- :mod:`~tdm.recording.scenario`: ``scenario.yaml``, the values the TDM uses;
- :mod:`~tdm.recording.description`: the two as a typed :class:`groundfloor.recording.RecordingDescription`
  (start time, duration, periods, ranges, mounts);
- :mod:`~tdm.recording.jsonl`: JSON-lines files, line by line;
- :mod:`~tdm.recording.ownship`: ``ownship.jsonl`` as checked columns;
- :mod:`~tdm.recording.npz`: ``.npz`` archives, headers before data, bounded loads;
- :mod:`~tdm.recording.sweeps`: the LiDAR and radar sweep arrays against their schema;
- :mod:`~tdm.recording.sweep_files`: the numbered sweep files and their order in time;
- :mod:`~tdm.recording.pcap_times`: PCAP packets inside the run and in time order;
- :mod:`~tdm.recording.land`: ``land.geojson``, the recording's land (the TDM's chart, :mod:`tdm.land`);
- :mod:`~tdm.recording.summary`: ``tdm info``, every file checked as far as headers go.

The PCAP's own structure (magic, link type, record lengths) is checked by :mod:`tdm.pcap`, the
NMEA lines (checksums, TAG blocks, fields) by :mod:`tdm.frontend.ais`.
"""
