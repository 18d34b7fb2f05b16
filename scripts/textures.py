#!/usr/bin/env python3
"""Writes the built-in `textures` scene's images into assets/textures/.

Everything is computed here (no third-party input, no licence to carry):
  checker.png     64 x 64 sRGB, 2 x 2 squares: the ground (moire case)
  globe.png       128 x 64 sRGB, a longitude/latitude grid with coloured bands
  bumps-normal.png 64 x 64 linear tangent-space normal map of round bumps
  sky.hdr         128 x 64 Radiance RGBE latitude-longitude environment:
                  a blue sky brightening to the horizon, a sun, a brown ground
and assets/models/checker-ground.obj: a 400 m square ground of 10 m tiles
with uv = (x, -z) / 400 (0 under the origin). Tiles rather than one huge
quad: interpolated uvs carry f32 rounding in proportion to the triangle's
size, and on a 400 m triangle that is a visible part of a texel.
Standard library only: python3 scripts/textures.py
"""
import math
import os
import struct
import zlib

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "assets", "textures")


def write_png(path, width, height, pixel):
    """pixel(x, y) -> (r, g, b) bytes; row 0 is the top."""
    raw = bytearray()
    for y in range(height):
        raw.append(0)
        for x in range(width):
            raw.extend(pixel(x, y))

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)

    png = b"\x89PNG\r\n\x1a\n"
    png += chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(bytes(raw), 9))
    png += chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(png)


def write_hdr(path, width, height, radiance):
    """radiance(x, y) -> (r, g, b) floats; flat (uncompressed) RGBE scanlines."""
    out = bytearray(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n")
    out += ("-Y %d +X %d\n" % (height, width)).encode()
    for y in range(height):
        for x in range(width):
            r, g, b = radiance(x, y)
            m = max(r, g, b)
            if m < 1e-32:
                out += bytes(4)
                continue
            mant, exp = math.frexp(m)
            scale = mant * 256.0 / m
            out += bytes([int(r * scale), int(g * scale), int(b * scale), exp + 128])
    with open(path, "wb") as f:
        f.write(out)


def checker(x, y):
    on = ((x // 32) + (y // 32)) % 2 == 0
    return (235, 235, 235) if on else (25, 25, 25)


def globe(x, y):
    lon_line = x % 16 == 0
    lat_line = y % 8 == 0
    if lon_line or lat_line:
        return (250, 250, 240)
    band = (y // 8) % 4
    base = [(40, 90, 170), (60, 150, 80), (200, 170, 90), (170, 60, 50)][band]
    shade = 0.75 + 0.25 * ((x // 16) % 2)
    return tuple(int(c * shade) for c in base)


def bumps(x, y):
    # Round bumps on an 16-texel grid: the height is a cosine cap; the
    # normal is (-dh/du, -dh/dv, 1) normalized, stored as n * 0.5 + 0.5.
    cx, cy = (x % 16) - 7.5, (y % 16) - 7.5
    r = math.hypot(cx, cy)
    if r >= 6.0:
        n = (0.0, 0.0, 1.0)
    else:
        slope = 0.6 * math.sin(math.pi * r / 6.0)
        # y grows down the image while v grows up: flip the v component.
        nx, ny = -slope * cx / max(r, 1e-6), slope * cy / max(r, 1e-6)
        length = math.sqrt(nx * nx + ny * ny + 1.0)
        n = (nx / length, ny / length, 1.0 / length)
    return tuple(int(round((c * 0.5 + 0.5) * 255)) for c in n)


def sky(x, y):
    w, h = 128, 64
    u, v = (x + 0.5) / w, 1.0 - (y + 0.5) / h
    lat = (v - 0.5) * math.pi
    lon = (u - 0.5) * 2.0 * math.pi
    d = (math.cos(lat) * math.sin(lon), math.sin(lat), -math.cos(lat) * math.cos(lon))
    if d[1] < 0.0:
        return (0.25, 0.18, 0.12)
    t = 1.0 - d[1]
    r, g, b = 0.25 + 0.55 * t ** 3, 0.45 + 0.4 * t ** 3, 1.0 - 0.1 * t
    sun = (0.5, 0.6, 0.62)
    norm = math.sqrt(sum(c * c for c in sun))
    cos_sun = sum(a * b2 / norm for a, b2 in zip(d, sun))
    if cos_sun > 0.995:
        r, g, b = r + 40.0, g + 36.0, b + 30.0
    return (r, g, b)


def write_ground(path, half=200.0, tiles=40):
    n = tiles + 1
    lines = ["# written by scripts/textures.py: %d x %d tiles, y = 0, facing +y" % (tiles, tiles)]
    for j in range(n):
        for i in range(n):
            x, z = -half + 2 * half * i / tiles, half - 2 * half * j / tiles
            lines.append("v %g 0 %g" % (x, z))
            lines.append("vt %g %g" % (x / (2 * half), -z / (2 * half)))
    for j in range(tiles):
        for i in range(tiles):
            a = j * n + i + 1
            b, c, d = a + 1, a + 1 + n, a + n
            lines.append("f %d/%d %d/%d %d/%d %d/%d" % (a, a, b, b, c, c, d, d))
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def main():
    os.makedirs(OUT, exist_ok=True)
    write_ground(os.path.join(OUT, "..", "models", "checker-ground.obj"))
    write_png(os.path.join(OUT, "checker.png"), 64, 64, checker)
    write_png(os.path.join(OUT, "globe.png"), 128, 64, globe)
    write_png(os.path.join(OUT, "bumps-normal.png"), 64, 64, bumps)
    write_hdr(os.path.join(OUT, "sky.hdr"), 128, 64, sky)


if __name__ == "__main__":
    main()
