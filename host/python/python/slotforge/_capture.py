"""Captures (decoded samples as numpy arrays) and the streaming decoder."""

import os

import numpy as np

from . import _native

# The decoder's columns, as the CSV of ``slotforge decode`` has them.
ROW = np.dtype(
    [
        ("frame", np.uint64),
        ("slice", np.uint16),
        ("mode", np.uint8),
        ("channel", np.uint16),
        ("value", np.uint16),
        ("sampled_s", np.float64),
    ]
)

# Read a file in pieces this large: the decoder streams, memory stays flat.
CHUNK = 1 << 20


def as_mix(mix):
    """A ``Mix`` from a path (or a Mix, as it is)."""
    if isinstance(mix, _native.Mix):
        return mix
    return _native.Mix(os.fspath(mix))


def _rows(columns):
    """The native decoder's column bytes as one structured array."""
    n = len(columns[4]) // 2
    rows = np.empty(n, dtype=ROW)
    for name, raw in zip(ROW.names, columns):
        rows[name] = np.frombuffer(raw, dtype=ROW[name])
    return rows


class Capture:
    """Decoded samples of a mix's link.

    ``channels``: the channels' names in the mix's order; ``cap[name]``:
    ``(t, v)``, ``t`` the sampling instants (float64 seconds after cycle 0,
    the ``sampled_s`` of ``slotforge decode``; NaN where the schedule has
    none), ``v`` the codes (int32); ``rows``: every sample in arrival order
    as a structured array (frame, slice, mode, channel, value, sampled_s);
    ``modes``/``mode``: a mix with modes, the modes' names and
    ``mode[name]``, the Capture of the rows whose packet's frame ran that
    mode.  Counts: ``packets``, ``lost``, ``crc_errors``, ``in_flight``
    (bytes of a packet still open at the end), and ``counts`` (all).
    """

    def __init__(self, mix, rows, counts):
        self.mix = mix
        self.rows = rows
        self.channels = list(mix.channels)
        self.modes = list(mix.modes)
        self.counts = dict(counts)

    packets = property(lambda self: self.counts["packets"])
    lost = property(lambda self: self.counts["lost"])
    crc_errors = property(lambda self: self.counts["crc_errors"])
    in_flight = property(lambda self: self.counts["in_flight"])
    clean = property(lambda self: self.counts["clean"])

    def __len__(self):
        return len(self.rows)

    def index(self, name):
        """A channel's position in the mix (KeyError naming the known ones)."""
        try:
            return self.channels.index(name)
        except ValueError:
            raise KeyError(
                f"mix `{self.mix.name}` has no channel {name!r} (it has {', '.join(self.channels)})"
            ) from None

    def __getitem__(self, name):
        rows = self.rows[self.rows["channel"] == self.index(name)]
        return rows["sampled_s"].copy(), rows["value"].astype(np.int32)

    def items(self):
        """``(name, (t, v))`` of every channel, in the mix's order."""
        return [(c, self[c]) for c in self.channels]

    @property
    def mode(self):
        """Mode name -> the Capture of that mode's rows ({} without modes)."""
        return {
            m: Capture(self.mix, self.rows[self.rows["mode"] == i], self.counts)
            for i, m in enumerate(self.modes)
        }

    def __repr__(self):
        return (
            f"<Capture of mix {self.mix.name}: {len(self.rows)} samples, "
            f"{self.packets} packets, {self.lost} lost, {self.crc_errors} CRC errors, "
            f"{self.in_flight} bytes in flight>"
        )


class Stream:
    """The decoder for any byte source: ``feed(bytes)`` returns a Capture
    of the samples of the packets those bytes complete (empty until a
    packet's trailer arrives); ``counts`` so far; ``close()`` the final
    counts (a packet still open counted in ``in_flight``)."""

    def __init__(self, mix):
        self.mix = as_mix(mix)
        self._dec = _native.Decoder(self.mix)
        self._final = None

    def feed(self, data):
        if self._final is not None:
            raise ValueError("the stream is closed")
        rows = _rows(self._dec.push(bytes(data)))
        return Capture(self.mix, rows, self.counts)

    @property
    def counts(self):
        if self._final is not None:
            return dict(self._final)
        c = self._dec.stats()
        c["in_flight"] = 0
        return c

    def close(self):
        if self._final is None:
            self._final = self._dec.finish()
        return dict(self._final)


def read(mix, path):
    """Decodes the file of the line's bytes at ``path`` (a serial-port
    dump, ``slotforge sim --link-bytes``) into a Capture."""
    s = Stream(mix)
    parts = []
    with open(path, "rb") as f:
        while True:
            data = f.read(CHUNK)
            if not data:
                break
            parts.append(s.feed(data).rows)
    rows = np.concatenate(parts) if parts else np.empty(0, dtype=ROW)
    return Capture(s.mix, rows, s.close())
