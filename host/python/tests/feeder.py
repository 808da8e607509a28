"""A separate process playing a board: once a line arrives on its stdin
(the reader has opened the port: pyserial flushes what came before),
writes FILE's bytes to the pseudo-terminal master FD at BYTES_PER_S (the
line's pace: baud over the bits of a character), prints how many and how
long it took, then keeps the terminal open until its stdin closes (so the
reader, not the feeder, decides when the line has ended).

    python feeder.py FD FILE BYTES_PER_S
"""

import os
import sys
import time


def main():
    fd, path, rate = int(sys.argv[1]), sys.argv[2], float(sys.argv[3])
    data = open(path, "rb").read()
    sys.stdin.readline()
    start, sent = time.monotonic(), 0
    while sent < len(data):
        # every byte whose last bit is due by now, in one write
        due = min(len(data), int((time.monotonic() - start) * rate) + 1)
        if due > sent:
            sent += os.write(fd, data[sent:due])
        else:
            time.sleep(0.002)
    print(f"{sent} {time.monotonic() - start:.6f}", flush=True)
    sys.stdin.read()


if __name__ == "__main__":
    main()
