#!/usr/bin/env python3
"""Renders a fluid-fraction map CSV (rows: time samples, columns: mid-plane angles 0..360° from
+x) to PNG with the same colours as the SVG (white φ = 0 → dark blue φ = 1); time runs left to
right, bearing angle bottom to top; a colour bar at the right. Stdlib only (zlib)."""
import sys, zlib, struct

def shade(phi):
    f = min(max(phi, 0.0), 1.0)
    return tuple(round(255 + (full - 255) * f) for full in (20, 50, 140))

def main(src, dst, cw=3, ch=6):
    rows = [[float(v) for v in line.split(',')] for line in open(src) if line.strip()]
    nt, na = len(rows), len(rows[0])
    bar = 40
    w, h = nt * cw + bar, na * ch
    img = []
    for y in range(h):
        k = na - 1 - y // ch  # angle index, 0° at the bottom
        line = bytearray([0])
        for x in range(nt * cw):
            line += bytes(shade(rows[x // cw][k]))
        for x in range(bar):
            line += bytes((255, 255, 255) if x < 10 else shade(1.0 - y / (h - 1)))
        img.append(bytes(line))
    raw = b''.join(img)
    def chunk(t, d):
        return struct.pack('>I', len(d)) + t + d + struct.pack('>I', zlib.crc32(t + d) & 0xffffffff)
    png = b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', w, h, 8, 2, 0, 0, 0))
    png += chunk(b'IDAT', zlib.compress(raw, 9)) + chunk(b'IEND', b'')
    open(dst, 'wb').write(png)

if __name__ == '__main__':
    main(sys.argv[1], sys.argv[2])
