"""slotforge.read and slotforge.Stream against `slotforge decode`."""

import math
import random

import numpy as np
import pytest

import slotforge
from conftest import ROOT, decode, link_presets, sim_bytes, unseen_mix


def assert_same(cap, dec):
    """A Capture equals decode's CSV row for row, per channel, and in its counts."""
    rows = cap.rows
    assert len(rows) == len(dec.rows) == dec.counts["samples"]
    names = [cap.channels[c] for c in rows["channel"]]
    assert names == [r["channel"] for r in dec.rows]
    assert rows["value"].tolist() == [int(r["value"]) for r in dec.rows]
    assert rows["frame"].tolist() == [int(r["frame"]) for r in dec.rows]
    assert rows["slice"].tolist() == [int(r["slice"]) for r in dec.rows]
    want_t = [float(r["sampled_s"]) if r["sampled_s"] else math.nan for r in dec.rows]
    np.testing.assert_array_equal(rows["sampled_s"], np.array(want_t))  # exact, not close
    if cap.modes:
        assert [cap.modes[m] for m in rows["mode"]] == [r["mode"] for r in dec.rows]
    for name in cap.channels:
        t, v = cap[name]
        mine = [r for r in dec.rows if r["channel"] == name]
        assert t.dtype == np.float64 and len(t) == len(v) == len(mine)
        assert v.tolist() == [int(r["value"]) for r in mine]
        assert t.tolist() == [float(r["sampled_s"]) for r in mine]
    c = dec.counts
    assert (cap.packets, cap.lost, cap.crc_errors, cap.in_flight) == (
        c["packets"], c["lost_packets"], c["crc_errors"], c["in_flight_bytes"])
    assert (cap.counts["resyncs"], cap.counts["skipped_bytes"], cap.counts["bytes"]) == (
        c["resyncs"], c["skipped_bytes"], c["bytes"])
    assert cap.clean == c["ok"]


@pytest.mark.parametrize("mix", link_presets(), ids=lambda p: p.stem)
def test_every_link_preset_reads_back_as_decode_gives_it(mix, tmp_path):
    line = tmp_path / "line.bin"
    sim_bytes(mix, line, frames=3)
    dec = decode(mix, line, tmp_path)
    cap = slotforge.read(mix, line)
    assert dec.code == 0 and len(cap) > 100 and cap.in_flight > 0
    assert_same(cap, dec)


def test_a_switching_mix_gives_its_modes_rows(tmp_path):
    mix = ROOT / "testkit/mixes/modes-auto.toml"
    line = tmp_path / "line.bin"
    sim_bytes(mix, line, frames=14, extra=["--stimulus", "touch:T0,T2@2-6"])
    dec = decode(mix, line, tmp_path)
    cap = slotforge.read(mix, line)
    assert_same(cap, dec)
    assert cap.modes == ["rest", "touch", "hold"]  # the mix's order
    by_mode = cap.mode
    assert list(by_mode) == cap.modes
    for m, sub in by_mode.items():
        want = [r for r in dec.rows if r["mode"] == m]
        assert len(sub) == len(want), m
        assert sub.rows["value"].tolist() == [int(r["value"]) for r in want]
    assert len(by_mode["rest"]) > 0 and len(by_mode["touch"]) > 0  # the run's switches


def test_an_unseen_uart_mix_reads_back_as_decode_gives_it(tmp_path):
    mix = unseen_mix(tmp_path, 'kind = "uart"\nbaud = 1_000_000\nparity = "even"\nstop_bits = 2\n')
    line = tmp_path / "line.bin"
    sim_bytes(mix, line, frames=5)
    assert_same(slotforge.read(mix, line), decode(mix, line, tmp_path))


def damaged(data, rng):
    """Corrupted and truncated forms of a clean stream."""
    out = []
    for _ in range(6):
        bad = bytearray(data)
        for _ in range(rng.randint(1, 4)):
            bad[rng.randrange(len(bad))] ^= 1 << rng.randrange(8)
        out.append(bytes(bad))
    for _ in range(4):
        out.append(data[: rng.randrange(1, len(data))])   # truncated
        out.append(data[rng.randrange(1, len(data) // 2):])  # joined mid-packet
    cut = rng.randrange(len(data) // 4, len(data) // 2)
    out.append(data[:cut] + data[cut + rng.randrange(1, 200):])  # bytes lost
    out.append(bytes(rng.randrange(256) for _ in range(500)) + data)  # garbage first
    return out


def test_corrupted_and_truncated_streams_give_decodes_counts(tmp_path):
    mix = ROOT / "mixes/eskin34-uart.toml"
    data = sim_bytes(mix, tmp_path / "line.bin", frames=2)
    rng = random.Random(43)
    for i, bad in enumerate(damaged(data, rng)):
        cap_file = tmp_path / f"bad{i}.bin"
        cap_file.write_bytes(bad)
        dec = decode(mix, cap_file, tmp_path)
        assert_same(slotforge.read(mix, cap_file), dec)
    assert any(not slotforge.read(mix, tmp_path / f"bad{i}.bin").clean for i in range(6))


def test_a_stream_fed_in_any_pieces_gives_the_files_samples(tmp_path):
    mix = ROOT / "mixes/eskin34-uart.toml"
    line = tmp_path / "line.bin"
    data = sim_bytes(mix, line, frames=2)
    whole = slotforge.read(mix, line)
    s = slotforge.Stream(mix)
    rng, at, parts = random.Random(7), 0, []
    while at < len(data):
        n = rng.choice([1, 3, 4, 17, 600])
        batch = s.feed(data[at:at + n])
        parts.append(batch.rows)
        at += n
    counts = s.close()
    assert np.concatenate(parts).tolist() == whole.rows.tolist()
    assert counts == whole.counts


def test_bad_input_is_told_in_the_users_words(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text((ROOT / "testkit/mixes/tiny.toml").read_text().replace("rate_hz = 4_000", "rate_hz = -4"))
    with pytest.raises(ValueError, match=r"bad\.toml:\d+"):
        slotforge.Mix(bad)
    with pytest.raises(ValueError, match="has no \\[link\\]"):
        slotforge.Stream(ROOT / "mixes/eskin34.toml")
    with pytest.raises(ValueError, match="AXI4-Stream has no serial port"):
        slotforge.open_serial(ROOT / "mixes/eskin34-axis.toml", "/dev/null")
    line = tmp_path / "line.bin"
    sim_bytes(ROOT / "mixes/eskin34-uart.toml", line, frames=1)
    cap = slotforge.read(ROOT / "mixes/eskin34-uart.toml", line)
    with pytest.raises(KeyError, match="has no channel 'CH99'"):
        cap["CH99"]
