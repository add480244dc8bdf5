"""Decode a real Navico HALO capture and draw its last revolution the way raysim draws its own PPIs.

    python docs/pictures/make_halo_picture.py CAPTURE.pcap [--out PNG]

``CAPTURE.pcap`` is a classic pcap (Ethernet, IPv4) of a HALO's network, such as the demo sample
``demo/samples/halo_and_0183.pcap`` of the public repository keesverruijt/mayara (commit
cbfe6a2). Its licence keeps it out of this repository: pass its path on the command line. The
script reassembles the IP fragments of the spoke stream (UDP 236.6.9.51:7059 by default), decodes
the spokes (layout: OpenCPN radar_pi ``src/navico/NavicoReceive.cpp``, ``br4g_header``; 8-byte
frame header, 32 spokes of a 24-byte header and 512 bytes of 4-bit samples, low nibble first;
angle and heading in 4096ths of a turn, heading bit 0x4000 = true; HALO range scale in metres =
largerange x smallrange / 512), keeps the last complete revolution, writes its north-up PPI with
:func:`raysim.recording.ppi.ppi_image` (same palette, rings and corner texts as raysim's pictures)
to ``halo_real_ppi.png`` next to this script, and prints the statistics of
:func:`echo_statistics` (the same numbers ``make_radar_pictures.py`` prints for raysim's pictures).
"""

from __future__ import annotations

import argparse
import datetime as dt
import struct
from collections import defaultdict
from pathlib import Path

import numpy as np
from scipy import ndimage

from raysim.recording.ppi import PpiLabels, ppi_image

HERE = Path(__file__).resolve().parent

FRAME_HEADER_BYTES = 8
SPOKE_HEADER_BYTES = 24
SPOKE_DATA_BYTES = 512
SPOKE_BYTES = SPOKE_HEADER_BYTES + SPOKE_DATA_BYTES
RAW_PER_TURN = 4096  # angle and heading units of a turn
HEADING_TRUE_FLAG = 0x4000
STRONG_LEVEL = 10  # "strong" echo: video level >= 10 of 15 (two thirds of full scale)
MAIN_BANG_SPOKES = 0.9  # a range sample lit on at least this share of the spokes is the main bang: left out
ARC_PEAK_LEVEL = 13  # a point-like echo this strong (the HALO's saturated level) should paint sidelobe arcs ...
ARC_DEG = (6.0, 20.0)  # ... on the spokes this far either side of it, at its range
POINT_MAX_RADIAL_M = 75.0  # "point-like" strong echo: a blob no longer than 75 m along range (3 HALO samples)


def read_pcap(path: Path):
    """Yield ``(time_s, ethernet_frame)`` of each record of a classic (not pcapng) capture file."""
    data = Path(path).read_bytes()
    magic = data[:4]
    if magic in (b"\xd4\xc3\xb2\xa1", b"\x4d\x3c\xb2\xa1"):
        endian = "<"
    elif magic in (b"\xa1\xb2\xc3\xd4", b"\xa1\xb2\x3c\x4d"):
        endian = ">"
    else:
        raise ValueError(f"{path}: not a classic pcap file")
    tick_s = 1e-9 if magic in (b"\x4d\x3c\xb2\xa1", b"\xa1\xb2\x3c\x4d") else 1e-6
    offset = 24
    while offset + 16 <= len(data):
        sec, frac, incl, _ = struct.unpack_from(endian + "IIII", data, offset)
        offset += 16
        yield sec + frac * tick_s, data[offset:offset + incl]
        offset += incl


def udp_datagrams(path: Path, group: str, port: int):
    """Yield ``(time_s, payload)`` of the UDP datagrams to ``group:port``, IP fragments reassembled.

    Fragments are collected per (source, destination, IP identification); a datagram is complete
    when the fragment without the more-fragments flag has arrived and the pieces leave no gap. Its
    time is that of its last fragment.
    """
    want = bytes(int(x) for x in group.split("."))
    pieces: dict[tuple, dict[int, bytes]] = defaultdict(dict)
    total: dict[tuple, int] = {}
    for time_s, frame in read_pcap(path):
        ethertype, ip = struct.unpack_from("!H", frame, 12)[0], 14
        if ethertype == 0x8100:  # 802.1Q tag
            ethertype, ip = struct.unpack_from("!H", frame, 16)[0], 18
        if ethertype != 0x0800 or frame[ip + 9] != 17 or frame[ip + 16:ip + 20] != want:
            continue
        ihl = (frame[ip] & 0x0F) * 4
        length, ident, flags_frag = struct.unpack_from("!HHH", frame, ip + 2)
        key = (frame[ip + 12:ip + 16], ident)
        frag_offset = (flags_frag & 0x1FFF) * 8
        pieces[key][frag_offset] = frame[ip + ihl:ip + length]
        if not flags_frag & 0x2000:
            total[key] = frag_offset + length - ihl
        if key in total and sum(len(p) for p in pieces[key].values()) >= total[key]:
            body = b"".join(pieces[key][o] for o in sorted(pieces[key]))
            del pieces[key], total[key]
            if struct.unpack_from("!H", body, 2)[0] == port:
                yield time_s, body[8:]


def decode_spokes(path: Path, group: str = "236.6.9.51", port: int = 7059) -> dict[str, np.ndarray]:
    """All spokes of the stream, in order of arrival.

    Returns
    -------
    dict
        ``time`` (s since the epoch, of the datagram), ``angle_raw`` and ``heading_raw``
        (4096ths, heading with its flags), ``range_m`` (range scale of the spoke),
        ``echo`` (S, 1024) uint8 levels 0..15.
    """
    times, angles, headings, ranges, echoes = [], [], [], [], []
    for time_s, frame in udp_datagrams(path, group, port):
        for start in range(FRAME_HEADER_BYTES, len(frame) - SPOKE_BYTES + 1, SPOKE_BYTES):
            header_len, status = frame[start], frame[start + 1]
            if header_len != SPOKE_HEADER_BYTES or status not in (0x02, 0x12):
                continue
            large, angle, heading, small = struct.unpack_from("<HHHH", frame, start + 6)
            packed = np.frombuffer(frame, np.uint8, SPOKE_DATA_BYTES, start + SPOKE_HEADER_BYTES)
            echo = np.empty(2 * SPOKE_DATA_BYTES, np.uint8)
            echo[0::2], echo[1::2] = packed & 0x0F, packed >> 4  # low nibble first (radar_pi)
            times.append(time_s)
            angles.append(angle)
            headings.append(heading)
            ranges.append(small / 4 if large == 0x80 else large * small / 512)
            echoes.append(echo)
    return dict(time=np.array(times), angle_raw=np.array(angles), heading_raw=np.array(headings),
                range_m=np.array(ranges, float), echo=np.array(echoes))


def last_revolution(spokes: dict[str, np.ndarray]) -> tuple[dict[str, np.ndarray], dict[str, float]]:
    """The spokes of the last complete turn (between the last two wraps of the antenna angle).

    Returns the turn's arrays and its timing: ``turns`` seen, ``spokes_per_turn``,
    ``rpm`` (from the angle advance over the whole capture), ``angle_step_raw``.
    """
    angle = spokes["angle_raw"].astype(np.int64) % RAW_PER_TURN
    wraps = np.flatnonzero(np.diff(angle) < 0) + 1
    if len(wraps) < 2:
        raise ValueError("the capture holds no complete revolution")
    turn = slice(wraps[-2], wraps[-1])
    unwrapped = angle + RAW_PER_TURN * np.concatenate([[0], np.cumsum(np.diff(angle) < 0)])
    elapsed_s = spokes["time"][-1] - spokes["time"][0]
    timing = dict(turns=len(wraps) - 1, spokes_per_turn=wraps[-1] - wraps[-2],
                  rpm=(unwrapped[-1] - unwrapped[0]) / RAW_PER_TURN / elapsed_s * 60.0,
                  angle_step_raw=float(np.median(np.diff(angle[turn]))),
                  spokes_per_s=(len(angle) - 1) / elapsed_s)
    return {k: v[turn] for k, v in spokes.items()}, timing


def _runs(mask: np.ndarray) -> np.ndarray:
    """Lengths of the runs of True along the last axis (samples), all spokes pooled."""
    padded = np.pad(mask.astype(np.int8), ((0, 0), (1, 1)))
    edges = np.diff(padded, axis=1)
    return np.flatnonzero(edges.ravel() == -1) - np.flatnonzero(edges.ravel() == 1)


def _blobs(echo: np.ndarray, mask: np.ndarray) -> dict[str, np.ndarray]:
    """Connected blobs of ``mask`` (8-connected, wrapping in azimuth), per blob: ``spokes`` and
    ``samples`` spanned, ``peak`` level of ``echo`` and the (``peak_spoke``, ``peak_sample``) where it is."""
    labels, count = ndimage.label(mask, structure=np.ones((3, 3), bool))
    first, last = labels[0], labels[-1]  # join blobs that cross spoke 0
    for a, b in set(zip(first[(first > 0) & (last > 0)], last[(first > 0) & (last > 0)])):
        labels[labels == b] = a
    out: dict[str, list] = {k: [] for k in ("spokes", "samples", "peak", "peak_spoke", "peak_sample")}
    for index in np.unique(labels[labels > 0]):
        rows, cols = np.nonzero(labels == index)
        spokes = np.unique(rows)
        gap = np.diff(np.concatenate([spokes, [spokes[0] + len(mask)]])).max()  # largest empty wedge
        top = np.argmax(echo[rows, cols])
        for key, value in zip(out, (len(mask) - gap + 1, cols.max() - cols.min() + 1, echo[rows[top], cols[top]],
                                    rows[top], cols[top])):
            out[key].append(value)
    return {k: np.array(v, dtype=np.int64) for k, v in out.items()}


def _arc_share(echo: np.ndarray, spoke: int, sample: int) -> float:
    """Share of the spokes ARC_DEG away either side of ``spoke`` with any echo within 1 sample of ``sample``."""
    spokes, samples = echo.shape
    lo, hi = (int(round(a * spokes / 360.0)) for a in ARC_DEG)
    offsets = np.concatenate([np.arange(-hi, -lo + 1), np.arange(lo, hi + 1)])
    rows = (spoke + offsets) % spokes
    cols = slice(max(sample - 1, 0), min(sample + 2, samples))
    return float((echo[rows, cols].max(axis=1) > 0).mean())


def echo_statistics(echo: np.ndarray, range_scale_m: float) -> dict[str, float]:
    """Numbers that compare one revolution's video with another's, whatever the range scale.

    Parameters
    ----------
    echo : (S, N) uint8
        Video levels 0..15 of one revolution, spokes in angle order.
    range_scale_m : float
        Range of the last sample, m (sample spacing ``range_scale_m / N``).

    Returns
    -------
    dict
        ``main_bang_samples`` (range samples lit on >= MAIN_BANG_SPOKES of the spokes, zeroed
        before everything else), ``histogram`` (fraction of cells at each
        level 0..15), ``nonzero`` (fraction of cells > 0), ``mode_nonzero`` (most common level > 0), ``strong`` (fraction >= STRONG_LEVEL);
        radial runs of strong cells along range: ``run_median_samples``, ``run_p90_samples``
        and the same in metres; strong point-like blobs (8-connected strong cells whose radial
        extent is at most POINT_MAX_RADIAL_M): ``points``, ``point_az_median_deg``, ``point_az_p90_deg``;
        sidelobe arcs: of the point-like echoes peaking at ARC_PEAK_LEVEL or more (``arc_points``),
        the median share of the spokes ARC_DEG either side with any echo at their range
        (``arc_share_median``; other echoes at that range count too: an upper bound);
        noise-floor speckle: ``isolated`` (fraction of all cells that are > 0 with all 8
        neighbours 0), ``isolated_share`` (those as a fraction of the non-zero cells),
        ``isolated_mean_level``.
    """
    spokes, samples = echo.shape
    dr_m = range_scale_m / samples
    bang = (echo > 0).mean(axis=0) >= MAIN_BANG_SPOKES
    echo = np.where(bang[None, :], 0, echo).astype(np.uint8)
    histogram = np.bincount(echo.ravel(), minlength=16)[:16] / echo.size
    strong = echo >= STRONG_LEVEL
    runs = _runs(strong)
    blobs = _blobs(echo, strong)
    point = blobs["samples"] * dr_m <= POINT_MAX_RADIAL_M
    point_az_deg = blobs["spokes"][point] * 360.0 / spokes
    arcs = [_arc_share(echo, a, r) for a, r in zip(blobs["peak_spoke"][point & (blobs["peak"] >= ARC_PEAK_LEVEL)],
                                                  blobs["peak_sample"][point & (blobs["peak"] >= ARC_PEAK_LEVEL)])]
    lit = echo > 0
    neighbours = ndimage.convolve(lit.astype(np.int16), np.ones((3, 3), np.int16), mode="wrap") - lit
    isolated = lit & (neighbours == 0)
    q = lambda x, p: float(np.percentile(x, p)) if len(x) else float("nan")  # noqa: E731
    return dict(
        main_bang_samples=int(bang.sum()), histogram=histogram, nonzero=float(lit.mean()),
        mode_nonzero=int(np.argmax(histogram[1:]) + 1), strong=float(strong.mean()),
        run_median_samples=q(runs, 50), run_p90_samples=q(runs, 90),
        run_median_m=q(runs, 50) * dr_m, run_p90_m=q(runs, 90) * dr_m,
        points=int(point.sum()), point_az_median_deg=q(point_az_deg, 50), point_az_p90_deg=q(point_az_deg, 90),
        arc_points=len(arcs), arc_share_median=q(arcs, 50),
        isolated=float(isolated.mean()), isolated_share=float(isolated.sum() / max(lit.sum(), 1)),
        isolated_mean_level=float(echo[isolated].mean()) if isolated.any() else float("nan"))


def format_statistics(name: str, stats: dict[str, float], range_scale_m: float, echo_shape: tuple[int, int]) -> str:
    """The statistics of :func:`echo_statistics` of an ``echo_shape`` (spokes, samples) revolution, as text."""
    spokes, samples = echo_shape
    hist = " ".join(f"{100 * h:.2f}" for h in stats["histogram"])
    return "\n".join([
        f"{name}: range scale {range_scale_m:.0f} m, {spokes} spokes, {samples} samples of {range_scale_m / samples:.2f} m",
        f"  main bang: {stats['main_bang_samples']} samples ({stats['main_bang_samples'] * range_scale_m / samples:.0f} m) "
        "lit on >= 90 % of the spokes, left out",
        f"  levels 0..15 (% of cells): {hist}",
        f"  non-zero {100 * stats['nonzero']:.2f} %, most common non-zero level {stats['mode_nonzero']}, "
        f"strong (>= {STRONG_LEVEL}) {100 * stats['strong']:.2f} %",
        f"  strong radial runs: median {stats['run_median_samples']:.0f} samples ({stats['run_median_m']:.0f} m), "
        f"90 % {stats['run_p90_samples']:.0f} samples ({stats['run_p90_m']:.0f} m)",
        f"  strong point-like echoes: {stats['points']}, azimuth width median {stats['point_az_median_deg']:.1f} deg, "
        f"90 % {stats['point_az_p90_deg']:.1f} deg",
        f"  sidelobe arcs: {stats['arc_points']} point-like echoes peaking >= {ARC_PEAK_LEVEL}, median share of the "
        f"spokes {ARC_DEG[0]:g}-{ARC_DEG[1]:g} deg either side lit at their range {100 * stats['arc_share_median']:.0f} %",
        f"  speckle: isolated non-zero cells {100 * stats['isolated']:.3f} % of all cells, "
        f"{100 * stats['isolated_share']:.1f} % of the non-zero ones, mean level {stats['isolated_mean_level']:.1f}",
    ])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("capture", type=Path, help="classic pcap of a HALO's network")
    parser.add_argument("--group", default="236.6.9.51", help="multicast group of the spoke stream")
    parser.add_argument("--port", type=int, default=7059, help="UDP port of the spoke stream")
    parser.add_argument("--out", type=Path, default=HERE / "halo_real_ppi.png", help="PNG to write")
    args = parser.parse_args(argv)
    spokes = decode_spokes(args.capture, args.group, args.port)
    turn, timing = last_revolution(spokes)
    heading_raw = turn["heading_raw"].astype(np.int64)
    heading_deg = (heading_raw & (RAW_PER_TURN - 1)) * 360.0 / RAW_PER_TURN
    azimuth_deg = (turn["angle_raw"] % RAW_PER_TURN) * 360.0 / RAW_PER_TURN
    scale_m = float(np.median(turn["range_m"]))
    range_m = np.linspace(0.0, scale_m, turn["echo"].shape[1])
    start = dt.datetime.fromtimestamp(float(spokes["time"][0]), dt.timezone.utc)
    ppi_image(turn["echo"], azimuth_deg, heading_deg, range_m, time_s=turn["time"] - spokes["time"][0],
              labels=PpiLabels(start_time=start)).save(args.out)
    print(args.out)
    print(f"{len(spokes['time'])} spokes in {spokes['time'][-1] - spokes['time'][0]:.2f} s, {timing['turns']} "
          f"complete turns; last turn {timing['spokes_per_turn']} spokes (angle step {timing['angle_step_raw']:g}/4096), "
          f"{timing['spokes_per_s']:.0f} spokes/s, {timing['rpm']:.1f} rpm; heading {heading_deg[0]:.1f} deg "
          f"({'true' if heading_raw[0] & HEADING_TRUE_FLAG else 'magnetic'}); range scales seen "
          f"{sorted(set(np.round(spokes['range_m']).astype(int).tolist()))} m")
    order = np.argsort(azimuth_deg, kind="stable")
    print(format_statistics("HALO", echo_statistics(turn["echo"][order], scale_m), scale_m, turn["echo"].shape))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
