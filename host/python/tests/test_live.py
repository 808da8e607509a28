"""Reading live: a pseudo-terminal fed at the line's real pace by a
separate process, read through slotforge.open_serial (pyserial at the
mix's baud, parity and stop bits) and `python -m slotforge.live`."""

import os
import pathlib
import pty
import subprocess
import sys
import time
import tty

import numpy as np
import pytest

import slotforge
from conftest import ROOT, sim_bytes, unseen_mix

FEEDER = pathlib.Path(__file__).with_name("feeder.py")


def pace(mix):
    """Bytes per second on the mix's UART: baud over a character's bits."""
    link = slotforge.Mix(mix).link
    bits = 1 + 8 + (link["parity"] != "none") + link["stop_bits"]
    return link["baud"] / bits


class Board:
    """A pseudo-terminal whose master a feeder process writes at the line's pace."""

    def __init__(self, line, rate):
        self.master, slave = pty.openpty()
        tty.setraw(slave)  # no echo, no line discipline before the reader configures it
        self.port = os.ttyname(slave)
        self.slave = slave
        self.feeder = subprocess.Popen(
            [sys.executable, str(FEEDER), str(self.master), str(line), str(rate)],
            pass_fds=[self.master], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        os.close(self.master)

    def go(self):
        """The reader has the port open: start the line."""
        self.feeder.stdin.write("go\n")
        self.feeder.stdin.flush()

    def done(self):
        """(bytes written, seconds the feeder took), the feeder then let go."""
        sent, took = self.feeder.stdout.readline().split()
        self.feeder.stdin.close()
        self.feeder.wait(timeout=10)
        os.close(self.slave)
        return int(sent), float(took)


@pytest.mark.parametrize("mix_of", ["preset", "unseen"])
def test_a_line_at_its_pace_reads_live_to_the_files_samples(mix_of, tmp_path):
    if mix_of == "preset":
        mix, frames = ROOT / "mixes/eskin34-uart.toml", 16
    else:
        link = 'kind = "uart"\nbaud = 1_000_000\nparity = "odd"\n'
        mix, frames = unseen_mix(tmp_path, link), 400
    line = tmp_path / "line.bin"
    data = sim_bytes(mix, line, frames=frames)
    rate = pace(mix)
    board = Board(line, rate)
    start = time.monotonic()
    live = slotforge.open_serial(mix, board.port, idle=0.5)
    board.go()
    batches = list(live)
    sent, took = board.done()
    want = slotforge.read(mix, line)
    got = np.concatenate([b.rows for b in batches])
    assert got.tolist() == want.rows.tolist()
    # live: the bytes came at the line's pace, the samples batch by batch
    assert sent == len(data) and took >= 0.9 * len(data) / rate, (took, len(data) / rate)
    assert len(batches) >= 5, len(batches)
    assert time.monotonic() - start >= took


def test_the_live_command_plots_a_line_into_a_file(tmp_path):
    mix = ROOT / "mixes/eskin34-uart.toml"
    line = tmp_path / "line.bin"
    sim_bytes(mix, line, frames=8)
    board = Board(line, pace(mix))
    png = tmp_path / "live.png"
    p = subprocess.Popen(
        [sys.executable, "-m", "slotforge.live", str(mix), board.port, "--save", str(png),
         "--idle", "0.5", "--window", "0.05"],
        stderr=subprocess.PIPE, text=True)
    opened = p.stderr.readline()
    assert opened.startswith(f"reading {board.port}"), opened
    board.go()
    err = p.stderr.read()
    assert p.wait(timeout=60) == 0, err
    board.done()
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "0 lost, 0 CRC errors" in err, err


def test_the_live_command_refuses_a_port_that_will_not_open(tmp_path):
    p = subprocess.run(
        [sys.executable, "-m", "slotforge.live", str(ROOT / "mixes/eskin34-uart.toml"),
         str(tmp_path / "no-such-port"), "--no-plot"],
        capture_output=True, text=True, timeout=60)
    assert p.returncode == 2 and "no-such-port" in p.stderr and "Traceback" not in p.stderr, p.stderr


class FakeLsl:
    """Stands in for pylsl: records each outlet's stream info and samples
    (a real outlet would announce itself on the network)."""

    def __init__(self):
        import types

        self.infos, self.pushed = [], {}
        fake = self

        class Desc:
            def __init__(self, labels):
                self.labels = labels

            def append_child(self, name):
                return self

            def append_child_value(self, key, value):
                self.labels.append(value)

        class StreamInfo:
            def __init__(self, name, kind, count, rate, fmt, source):
                self.fields = dict(name=name, kind=kind, count=count, rate=rate, fmt=fmt, source=source)
                self.labels = []
                fake.infos.append(self)

            def desc(self):
                return Desc(self.labels)

        class StreamOutlet:
            def __init__(self, info):
                self.name = info.fields["name"]
                fake.pushed[self.name] = []

            def push_sample(self, sample):
                fake.pushed[self.name].append(list(sample))

        self.module = types.ModuleType("pylsl")
        self.module.StreamInfo, self.module.StreamOutlet = StreamInfo, StreamOutlet


def test_lsl_has_an_outlet_per_rate_group_and_a_sample_per_round(tmp_path, monkeypatch):
    mix = slotforge.Mix(ROOT / "mixes/eskin34-uart.toml")
    line = tmp_path / "line.bin"
    sim_bytes(mix_path := ROOT / "mixes/eskin34-uart.toml", line, frames=2)
    cap = slotforge.read(mix_path, line)
    lsl = FakeLsl()
    monkeypatch.setitem(sys.modules, "pylsl", lsl.module)
    from slotforge.live import Outlets, rate_groups

    groups = rate_groups(mix)
    assert [(r, len(c)) for r, c in groups] == [(2000, 2), (1000, 30), (100, 9)]
    out = Outlets(mix, groups)
    half = len(cap.rows) // 2  # in two batches, as a live line gives them
    for part in (cap.rows[:half], cap.rows[half:]):
        out.push(slotforge.Capture(mix, part, cap.counts))
    for info, (rate, chans) in zip(lsl.infos, groups):
        f = info.fields
        assert (f["name"], f["kind"], f["count"], f["rate"], f["fmt"]) == (
            f"eskin34-uart {rate} Hz", "slotforge", len(chans), rate, "int32")
        assert info.labels == [mix.channels[c] for c in chans]
        codes = [cap[mix.channels[c]][1].tolist() for c in chans]
        rounds = min(len(c) for c in codes)
        assert rounds > 0
        assert lsl.pushed[f["name"]] == [[c[k] for c in codes] for k in range(rounds)]


def test_lsl_without_pylsl_is_told(tmp_path):
    code = ("import sys; sys.modules['pylsl'] = None; from slotforge.live import main; "
            f"sys.exit(main([{str(ROOT / 'mixes/eskin34-uart.toml')!r}, '/dev/null', '--lsl', '--no-plot']))")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert p.returncode == 2 and "--lsl needs pylsl (pip install pylsl)" in p.stderr, p.stderr
    assert "Traceback" not in p.stderr
