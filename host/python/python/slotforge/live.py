"""``python -m slotforge.live MIX PORT``: a live board's samples, plotted.

One row of the figure per rate group (the channels of one rate, the rate
in the row's title), the last ``--window`` seconds of each channel;
``--lsl`` also publishes a Lab Streaming Layer outlet per rate group (with
pylsl installed); ``--save PNG`` draws the figure into a file when the
line ends instead of a window (``--idle`` ends it after that many seconds
without a byte).  Exit 0: a clean line; 1: losses or CRC errors; 2: bad
input (the mix, the port, pylsl missing).
"""

import argparse
import sys
import threading
import time
from collections import defaultdict, deque

from ._capture import as_mix
from ._serial import open_serial


def rate_groups(mix):
    """``[(rate_hz, [channel index])]``, fastest first, channels in mix order."""
    groups = defaultdict(list)
    for i, r in enumerate(mix.rates):
        groups[r].append(i)
    return sorted(groups.items(), key=lambda g: -g[0])


class Outlets:
    """One LSL outlet per rate group: a sample of the group's every channel
    once each has a new value (channels of one rate are sampled equally often)."""

    def __init__(self, mix, groups):
        try:
            import pylsl
        except ImportError as e:
            raise ValueError(f"--lsl needs pylsl (pip install pylsl): {e}") from None
        self.outlets = []
        for rate, chans in groups:
            info = pylsl.StreamInfo(
                f"{mix.name} {rate} Hz", "slotforge", len(chans), rate, "int32",
                f"slotforge-{mix.name}-{rate}",
            )
            labels = info.desc().append_child("channels")
            for c in chans:
                labels.append_child("channel").append_child_value("label", mix.channels[c])
            self.outlets.append((pylsl.StreamOutlet(info), chans, [deque() for _ in chans]))

    def push(self, batch):
        for outlet, chans, queues in self.outlets:
            for q, c in zip(queues, chans):
                q.extend(batch.rows["value"][batch.rows["channel"] == c].tolist())
            while all(queues):
                outlet.push_sample([q.popleft() for q in queues])


class Traces:
    """The last ``window`` seconds of every channel, filled by the reader."""

    def __init__(self, n, window):
        self.window = window
        self.t = [deque() for _ in range(n)]
        self.v = [deque() for _ in range(n)]
        self.lock = threading.Lock()

    def add(self, batch):
        rows = batch.rows
        with self.lock:
            for c, t, v in zip(rows["channel"].tolist(), rows["sampled_s"].tolist(), rows["value"].tolist()):
                if c < len(self.t):
                    self.t[c].append(t)
                    self.v[c].append(v)
            end = rows["sampled_s"][-1] if len(rows) else None
            if end is not None:
                for t, v in zip(self.t, self.v):
                    while t and t[0] < end - self.window:
                        t.popleft()
                        v.popleft()


def figure(mix, groups, plt):
    fig, axes = plt.subplots(len(groups), 1, sharex=True, squeeze=False,
                             figsize=(10, 2.2 * len(groups) + 0.8))
    lines = []
    for ax, (rate, chans) in zip(axes[:, 0], groups):
        ax.set_title(f"{rate} Hz: {len(chans)} channel{'s' if len(chans) != 1 else ''}", loc="left", fontsize=9)
        ax.set_ylabel("code")
        for c in chans:
            (ln,) = ax.plot([], [], lw=0.8, label=mix.channels[c])
            lines.append((c, ax, ln))
        if len(chans) <= 8:
            ax.legend(loc="upper right", fontsize=7)
    axes[-1, 0].set_xlabel("sampled_s (s after the first cycle)")
    fig.suptitle(f"slotforge mix {mix.name}")
    return fig, lines


def redraw(traces, lines):
    with traces.lock:
        for c, ax, ln in lines:
            ln.set_data(list(traces.t[c]), list(traces.v[c]))
    for ax in {ax for _, ax, _ in lines}:
        ax.relim()
        ax.autoscale_view()


def main(argv=None):
    p = argparse.ArgumentParser(prog="python -m slotforge.live", description=__doc__.split("\n\n")[0])
    p.add_argument("mix", help="the channel-mix file (TOML) with a UART [link]")
    p.add_argument("port", help="the serial port (/dev/ttyUSB0, COM3, a pseudo-terminal)")
    p.add_argument("--window", type=float, default=2.0, help="seconds of each trace shown (default 2)")
    p.add_argument("--lsl", action="store_true", help="publish an LSL outlet per rate group (needs pylsl)")
    p.add_argument("--no-plot", action="store_true", help="no figure (with --lsl: a headless bridge)")
    p.add_argument("--save", metavar="PNG", help="draw the figure into PNG when the line ends, no window")
    p.add_argument("--idle", type=float, default=None, help="end after this many seconds without a byte")
    a = p.parse_args(argv)
    try:
        mix = as_mix(a.mix)
        groups = rate_groups(mix)
        outlets = Outlets(mix, groups) if a.lsl else None
        live = open_serial(mix, a.port, idle=a.idle)
    except (ValueError, OSError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    except Exception as e:  # pyserial's SerialException: a port that will not open
        print(f"error: {a.port}: {e}", file=sys.stderr)
        return 2
    link = mix.link
    print(f"reading {a.port} at {link['baud']} baud, parity {link['parity']}, "
          f"{link['stop_bits']} stop bit{'s' if link['stop_bits'] > 1 else ''}",
          file=sys.stderr, flush=True)
    traces = Traces(len(mix.channels), a.window)
    done = threading.Event()

    def reader():
        try:
            for batch in live:
                traces.add(batch)
                if outlets:
                    outlets.push(batch)
        finally:
            done.set()

    threading.Thread(target=reader, daemon=True).start()
    if a.no_plot:
        done.wait()
    else:
        import matplotlib

        if a.save:
            matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, lines = figure(mix, groups, plt)
        if a.save:
            done.wait()
            redraw(traces, lines)
            fig.savefig(a.save, dpi=80)
        else:
            plt.show(block=False)
            while not done.is_set() and plt.fignum_exists(fig.number):
                redraw(traces, lines)
                plt.pause(0.2)
    c = live.counts
    print(
        f"{a.port}: {c['bytes']} bytes, {c['packets']} packets, {c['samples']} samples; "
        f"{c['lost']} lost, {c['crc_errors']} CRC errors, {c['in_flight']} bytes in flight"
        f" ({live.ended or 'window closed'})",
        file=sys.stderr,
    )
    return 0 if c["clean"] else 1


if __name__ == "__main__":
    sys.exit(main())
