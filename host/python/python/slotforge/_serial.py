"""A live serial port, decoded batch by batch."""

import time

from ._capture import Stream, as_mix


def _line(mix):
    """The UART settings of the mix's ``[link]`` (ValueError if it has none)."""
    link = mix.link
    if link is None:
        raise ValueError(f"mix `{mix.name}` has no [link]: there is no serial line to read")
    if link["kind"] != "uart":
        raise ValueError(
            f"mix `{mix.name}`: link.kind is \"{link['kind']}\": an AXI4-Stream has no serial "
            "port (read a dump of its beats with slotforge.read)"
        )
    return link


class SerialStream:
    """Batches (Captures) from a serial port as packets complete.

    Iteration ends when the port goes away (a board unplugged, the other
    end of a pseudo-terminal closed) or after ``idle`` seconds without a
    byte (``idle=None``: never); ``counts`` then holds the final counts and
    ``ended`` why it ended.
    """

    def __init__(self, mix, port, idle=None, timeout=0.05):
        import serial

        self._serial = serial
        self.mix = as_mix(mix)
        link = _line(self.mix)
        parity = {"none": serial.PARITY_NONE, "even": serial.PARITY_EVEN, "odd": serial.PARITY_ODD}
        stop = {1: serial.STOPBITS_ONE, 2: serial.STOPBITS_TWO}
        self.port = serial.Serial(
            port,
            baudrate=link["baud"],
            bytesize=serial.EIGHTBITS,
            parity=parity[link["parity"]],
            stopbits=stop[link["stop_bits"]],
            timeout=timeout,
        )
        self.stream = Stream(self.mix)
        self.idle = idle
        self.ended = None

    @property
    def counts(self):
        return self.stream.counts

    def __iter__(self):
        quiet = time.monotonic()
        try:
            while True:
                try:
                    data = self.port.read(max(1, self.port.in_waiting))
                except (self._serial.SerialException, OSError) as e:
                    self.ended = f"the port closed: {e}"
                    break
                now = time.monotonic()
                if data:
                    quiet = now
                    batch = self.stream.feed(data)
                    if len(batch):
                        yield batch
                elif self.idle is not None and now - quiet >= self.idle:
                    self.ended = f"no byte for {self.idle} s"
                    break
        finally:
            self.close()

    def close(self):
        self.port.close()
        return self.stream.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def open_serial(mix, port, idle=None, timeout=0.05):
    """Opens ``port`` with pyserial at the mix's baud, parity and stop bits;
    iterate the result for batches (Captures) as packets complete."""
    return SerialStream(mix, port, idle=idle, timeout=timeout)
