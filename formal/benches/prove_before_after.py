#!/usr/bin/env python3
"""Cold proofs at an earlier commit and at the working tree, side by side in
one run (`make bench-prove`; docs/performance.md, "Formal proof").

    python3 formal/benches/prove_before_after.py [--base REV] [--rounds N] [MIX ...]

Builds `slotforge` (release) at REV, in a temporary git worktree with a
target directory of its own (cargo would take one build for the other: their
paths inside the workspace are the same), and at the working tree. Then, for
each round and each mix (default: every preset), runs `slotforge prove MIX
--json` with each binary in turn, each time with empty proof and tool caches
(`SLOTFORGE_CACHE` and `XDG_CACHE_HOME` a fresh directory), so every proof is
cold and the two see the same machine load. Prints each run's wall and CPU
seconds (this process's children: the binary and its yosys), its result and
depth; then per mix the median wall of each binary and the ratio REV / now.
Exits 1 if a mix's result, depth or count of parts not covered differs
between the two binaries (a speed-up that changes a verdict is not one).
"""

import argparse
import json
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def build(tree: Path, target: Path) -> Path:
    """`slotforge` built in release at `tree` into `target`."""
    subprocess.run(
        ["cargo", "build", "--release", "--locked", "-q", "-p", "slotforge"],
        cwd=tree,
        env={**os.environ, "CARGO_TARGET_DIR": str(target)},
        check=True,
    )
    exe = target / "release" / "slotforge"
    if not exe.is_file():
        sys.exit(f"slotforge did not build in {tree}")
    return exe


def prove(exe: Path, mix: Path) -> dict:
    """One cold proof: wall and CPU seconds, result, depth, parts not covered."""
    cache = tempfile.mkdtemp(prefix="prove-bench-")
    env = {**os.environ, "SLOTFORGE_CACHE": cache, "XDG_CACHE_HOME": cache}
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.monotonic()
    out = subprocess.run(
        [str(exe), "prove", str(mix), "--json"], env=env, capture_output=True, text=True
    )
    wall = time.monotonic() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    shutil.rmtree(cache, ignore_errors=True)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    try:
        j = json.loads(out.stdout)
    except json.JSONDecodeError:
        sys.exit(f"{exe} prove {mix}: exit {out.returncode}, no JSON:\n{out.stderr}")
    return {
        "wall": wall,
        "cpu": cpu,
        "result": j["result"],
        "depth": j["depth"],
        "not_covered": len(j["not_covered"]),
    }


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--base", default="a03a29f", help="the earlier commit (default: %(default)s)")
    ap.add_argument("--rounds", type=int, default=2, help="rounds of every mix (default: 2)")
    ap.add_argument("mixes", nargs="*", type=Path, help="mixes (default: mixes/*.toml)")
    a = ap.parse_args()
    mixes = a.mixes or sorted((ROOT / "mixes").glob("*.toml"))
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    with tempfile.TemporaryDirectory() as tmp:
        wt = Path(tmp) / "base"
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", "-q", str(wt), a.base], check=True)
        try:
            base = build(wt, target / "prove-bench-base")
            now = build(ROOT, target)
            runs = {(m, who): [] for m in mixes for who in ("base", "now")}
            for r in range(1, a.rounds + 1):
                for m in mixes:
                    for who, exe in (("base", base), ("now", now)):
                        p = prove(exe, m)
                        runs[(m, who)].append(p)
                        print(
                            f"round {r} {m.name:<28} {who:<4} {p['wall']:7.1f} s wall "
                            f"{p['cpu']:7.1f} s CPU  {p['result']}, depth {p['depth']}, "
                            f"{p['not_covered']} not covered",
                            flush=True,
                        )
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(wt)], check=False)
    differ = 0
    print(f"\nmedian wall over {a.rounds} round(s), {a.base} -> working tree:")
    for m in mixes:
        b, n = runs[(m, "base")], runs[(m, "now")]
        key = lambda p: (p["result"], p["depth"], p["not_covered"])
        same = {key(p) for p in b + n}
        bw, nw = statistics.median(p["wall"] for p in b), statistics.median(p["wall"] for p in n)
        note = "" if len(same) == 1 else f"  VERDICTS DIFFER: {sorted(same)}"
        differ += len(same) != 1
        print(f"  {m.name:<28} {bw:7.1f} -> {nw:7.1f} s  ({bw / max(nw, 1e-9):.2f}x){note}")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
