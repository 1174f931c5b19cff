#!/usr/bin/env python3
"""Compares two `rotor-twin bench --trace` files step by step (issue 17): the largest difference of
the journal positions over their common steps, absolute (m) and relative to the largest position
magnitude of the reference (the first file). Usage: compare_trace.py OLD NEW [BEARINGS]."""
import struct
import sys


def read(path, width):
    data = open(path, "rb").read()
    n = len(data) // (8 * width)
    return [struct.unpack_from("<%dd" % width, data, 8 * width * i) for i in range(n)]


def main():
    old_path, new_path = sys.argv[1], sys.argv[2]
    bearings = int(sys.argv[3]) if len(sys.argv) > 3 else 2
    width = 1 + 2 * bearings
    old, new = read(old_path, width), read(new_path, width)
    n = min(len(old), len(new))
    if n == 0:
        sys.exit("no common steps")
    worst, worst_step, scale, time_diff = 0.0, 0, 0.0, 0.0
    for k in range(n):
        time_diff = max(time_diff, abs(old[k][0] - new[k][0]))
        for a, b in zip(old[k][1:], new[k][1:]):
            scale = max(scale, abs(a))
            if abs(a - b) > worst:
                worst, worst_step = abs(a - b), k
    print(f"{n} common steps ({len(old)} and {len(new)}); largest journal position difference "
          f"{worst:.3e} m at step {worst_step} = {worst / scale:.3e} of the largest position "
          f"{scale:.3e} m; largest time difference {time_diff:.3e} s")


if __name__ == "__main__":
    main()
