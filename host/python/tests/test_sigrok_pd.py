"""The sigrok decoder `slotforge sigrok` writes, fed the line's bytes as
sigrok's uart decoder hands them over (a stand-in for libsigrokdecode's
module), on clean, corrupted and cut streams: the packets it annotates as
good carry exactly `slotforge decode`'s records, and it reports one bad
CRC per CRC error decode counts.  (tests/host_sigrok.rs runs it in
sigrok-cli itself on a simulation's waveform.)"""

import importlib.util
import random
import subprocess
import sys
import types

from conftest import ROOT, binary, decode, sim_bytes


def load_pd(mix, tmp_path):
    out = tmp_path / "decoders"
    p = subprocess.run([binary(), "sigrok", str(mix), "-o", str(out)], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    (pd_dir,) = out.iterdir()
    srd = types.ModuleType("sigrokdecode")
    srd.Decoder, srd.OUTPUT_ANN = object, 0
    sys.modules["sigrokdecode"] = srd
    spec = importlib.util.spec_from_file_location("pd_under_test", pd_dir / "pd.py")
    pd = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(pd)
    return pd


def annotations(pd, data):
    """(class, text) of every annotation, bytes fed one UART 'DATA' each."""
    anns = []
    d = pd.Decoder()
    d.register = lambda kind: kind
    d.put = lambda ss, es, out, a: anns.append((ss, a[0], a[1][0]))
    d.start()
    for i, b in enumerate(data):
        d.decode(10 * i, 10 * i + 9, ["DATA", 0, (b, [])])
    names = [c[0] for c in pd.Decoder.annotations]
    # a packet's annotations come at its trailer, so order by sample
    return [(names[k], text) for _, k, text in sorted(anns, key=lambda a: a[0])]


def test_the_decoders_good_packets_are_decodes_on_any_stream(tmp_path):
    mix = ROOT / "mixes/eskin34-uart.toml"
    data = sim_bytes(mix, tmp_path / "line.bin", frames=2)
    pd = load_pd(mix, tmp_path)
    rng = random.Random(9)
    streams = [data, data[: len(data) // 3], data[777:]]
    for _ in range(5):
        bad = bytearray(data)
        bad[rng.randrange(len(bad))] ^= 1 << rng.randrange(8)
        streams.append(bytes(bad))
    for i, s in enumerate(streams):
        f = tmp_path / f"s{i}.bin"
        f.write_bytes(s)
        dec = decode(mix, f, tmp_path)
        anns = annotations(pd, s)
        records = [t for k, t in anns if k == "record"]
        assert records == [f"{r['channel']}: {r['value']}" for r in dec.rows], i
        assert sum(k == "trailer" for k, _ in anns) == dec.counts["packets"], i
        assert sum(k == "crc-bad" for k, _ in anns) == dec.counts["crc_errors"], i
        assert sum(k == "skipped" for k, _ in anns) <= dec.counts["skipped_bytes"], i
