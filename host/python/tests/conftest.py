"""The package's tests hold it to the CLI: the bytes `slotforge sim
--link-bytes` writes, read by the package, equal `slotforge decode`'s CSV.

The binary is $SLOTFORGE, else the workspace's debug build
(target/debug/slotforge, what `make test` built), else the release one.
"""

import csv
import io
import json
import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]


def binary():
    if os.environ.get("SLOTFORGE"):
        return os.environ["SLOTFORGE"]
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    for profile in ("debug", "release"):
        p = target / profile / "slotforge"
        if p.exists():
            return str(p)
    pytest.fail("no slotforge binary: build it (cargo build) or set SLOTFORGE")


def link_presets():
    """Every preset mix with a [link] (mixes/*.toml)."""
    return sorted(p for p in (ROOT / "mixes").glob("*.toml") if "\n[link]" in p.read_text())


def sim_bytes(mix, out, frames=2, extra=()):
    """`slotforge sim MIX --backend model --link-bytes OUT`: the line's bytes."""
    subprocess.run(
        [binary(), "sim", str(mix), "--backend", "model", "--frames", str(frames), "--quiet",
         "--link-bytes", str(out), *extra],
        check=True, cwd=ROOT,
    )
    return pathlib.Path(out).read_bytes()


class Decoded:
    """`slotforge decode`'s exit code, counts (--json) and CSV rows."""

    def __init__(self, code, counts, rows):
        self.code, self.counts, self.rows = code, counts, rows


def decode(mix, capture, tmp):
    out = pathlib.Path(tmp) / "decoded.csv"
    p = subprocess.run([binary(), "decode", str(mix), str(capture), "-o", str(out), "--json"],
                       capture_output=True, text=True, cwd=ROOT)
    assert p.returncode in (0, 1), p.stderr
    rows = list(csv.DictReader(io.StringIO(out.read_text())))
    return Decoded(p.returncode, json.loads(p.stdout), rows)


def unseen_mix(tmp, link):
    """The tiny two-branch mix with a `[link]` of ours (a mix no preset has)."""
    text = (ROOT / "testkit/mixes/tiny.toml").read_text()
    mix = pathlib.Path(tmp) / "unseen.toml"
    mix.write_text(text.replace('name = "tiny"', 'name = "unseen-uart"') + "\n[link]\n" + link)
    return mix


@pytest.fixture
def root():
    return ROOT
