"""slotforge's link to the host, read into numpy.

The bytes a mix's link carries (docs/packet-format.md) are decoded by the
Rust decoder that ``slotforge decode`` runs (``slotforge._native``); each
sample gets its channel's name and its sampling instant from the mix's
schedule, the same ``sampled_s`` the CLI writes.

    import slotforge
    cap = slotforge.read("mixes/eskin34-uart.toml", "line.bin")
    t, v = cap["CH7"]                  # seconds after cycle 0, ADC codes
    cap.packets, cap.lost, cap.crc_errors, cap.in_flight

    s = slotforge.Stream("mixes/eskin34-uart.toml")
    batch = s.feed(some_bytes)         # the samples those bytes complete

    for batch in slotforge.open_serial("mixes/eskin34-uart.toml", "/dev/ttyUSB0"):
        ...                            # live, batch by batch

``python -m slotforge.live MIX PORT`` plots a live board (``--lsl``: a Lab
Streaming Layer outlet per rate group).  docs/host.md has the details.
"""

from ._native import Mix
from ._capture import Capture, Stream, read
from ._serial import SerialStream, open_serial

__all__ = ["Mix", "Capture", "Stream", "read", "open_serial", "SerialStream"]
