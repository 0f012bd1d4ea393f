#!/usr/bin/env python3
"""Writes the seed corpora of the fuzz targets (fuzz/corpus/<target>/).

Run from the repository root: python3 fuzz/make_seeds.py. Plain Python (zlib,
struct) so it needs nothing beyond the standard library. The byte layouts are
the ones fuzz/detect_case.h and fuzz/grid_decode_case.h read. Two seeds of
detect_fuzzer are not made here: jpeg_checker and tiff_colour_checker are the
mode bytes followed by a 48x40 checkerboard written by cv::imencode (JPEG
quality 70, TIFF 3-channel).
"""
import math
import os
import struct
import zlib

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus")


def checker(width, height, tile, angle=0.3, x0=None, y0=None, samples=3):
    """Anti-aliased rotated checkerboard, grey values in [0, 1]."""
    x0 = width / 2.0 if x0 is None else x0
    y0 = height / 2.0 if y0 is None else y0
    c, s = math.cos(angle), math.sin(angle)
    rows = []
    for y in range(height):
        row = []
        for x in range(width):
            acc = 0.0
            for sy in range(samples):
                for sx in range(samples):
                    dx = x + (sx + 0.5) / samples - 0.5 - x0
                    dy = y + (sy + 0.5) / samples - 0.5 - y0
                    u = (c * dx + s * dy) / tile
                    v = (-s * dx + c * dy) / tile
                    acc += 0.85 if (math.floor(u) + math.floor(v)) % 2 else 0.15
            row.append(acc / samples / samples)
        rows.append(row)
    return rows


def png(rows, bit_depth=8, colour_type=0):
    """colour_type 0 = grey, 6 = RGBA (grey replicated, alpha opaque)."""
    height, width = len(rows), len(rows[0])
    raw = bytearray()
    for row in rows:
        raw.append(0)
        for value in row:
            if bit_depth == 16:
                sample = struct.pack(">H", int(round(value * 65535)))
            else:
                sample = bytes([int(round(value * 255))])
            if colour_type == 6:
                raw += sample * 3 + (b"\xff\xff" if bit_depth == 16 else b"\xff")
            else:
                raw += sample

    def chunk(kind, body):
        return (struct.pack(">I", len(body)) + kind + body +
                struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF))

    header = struct.pack(">IIBBBBB", width, height, bit_depth, colour_type, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) +
            chunk(b"IDAT", zlib.compress(bytes(raw), 9)) + chunk(b"IEND", b""))


def bmp24(rows):
    height, width = len(rows), len(rows[0])
    stride = (width * 3 + 3) & ~3
    pixels = bytearray()
    for row in reversed(rows):
        line = bytearray()
        for value in row:
            g = int(round(value * 255))
            line += bytes([g, g, g])
        pixels += line + b"\0" * (stride - len(line))
    header = struct.pack("<2sIHHI", b"BM", 54 + len(pixels), 0, 0, 54)
    info = struct.pack("<IiiHHIIiiII", 40, width, height, 1, 24, 0, len(pixels),
                       2835, 2835, 0, 0)
    return header + info + bytes(pixels)


def u16(value):
    return struct.pack("<H", value)


def unit16(fraction):
    return u16(int(round(min(max(fraction, 0.0), 1.0) * 65535)))


def write(target, name, data):
    folder = os.path.join(ROOT, target)
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, name), "wb") as f:
        f.write(data)


def detect_seeds():
    t = "detect_fuzzer"
    # Mode byte (even: encoded file, odd: raw buffer), then an options byte.
    write(t, "png8_checker", b"\x00\x00" + png(checker(64, 48, 8)))
    write(t, "png16_checker", b"\x00\x01" + png(checker(40, 40, 7, 0.7), 16))
    write(t, "png_rgba_checker", b"\x00\x00" + png(checker(32, 32, 6), 8, 6))
    write(t, "bmp_checker", b"\x00\x08" + bmp24(checker(40, 30, 6, -0.4)))
    # Raw 8-bit: width-1, height-1 as U16 (IntInRange(1, 256)), type byte 0.
    rows = checker(64, 64, 9, 0.2)
    raw = bytes(int(round(v * 255)) for row in rows for v in row)
    write(t, "raw8_checker", b"\x01\x00" + u16(63) + u16(63) + b"\x00" + raw)
    # Raw float with NaN and inf pixels (type byte 2).
    rows = checker(24, 24, 5, 0.5)
    values = [v for row in rows for v in row]
    values[100] = float("nan")
    values[200] = float("inf")
    raw = b"".join(struct.pack("<f", v) for v in values)
    write(t, "rawf32_nan", b"\x01\x03" + u16(23) + u16(23) + b"\x02" + raw)
    write(t, "tiny", b"\x01\x00" + u16(0) + u16(0) + b"\x00\x80")


def lattice_header(board, image, options, mode, ox, oy, spacing, angle):
    """Fields of fuzz/grid_decode_case.h up to the corner bytes."""
    return (bytes([board, image, options, mode]) +
            unit16((ox + 40) / 400.0) + unit16((oy + 40) / 320.0) +
            unit16((spacing - 0.5) / 59.5) + unit16((angle + math.pi) / (2 * math.pi)))


def lattice_corners(cols, rows, noise, flags_fn):
    out = u16(cols - 1) + u16(rows - 1) + unit16(noise / 0.5)
    for j in range(rows):
        for i in range(cols):
            out += bytes([flags_fn(i, j)]) + unit16(0.5) + unit16(0.5)
    return out


def grid_decode_seeds():
    t = "grid_decode_fuzzer"
    # Clean 11 x 8 lattice on a checkerboard image, checkerboard board.
    write(t, "checker_11x8_clean",
          lattice_header(2, 1, 0x08, 0, 40, 40, 22, 0.1) +
          lattice_corners(11, 8, 0.0, lambda i, j: 1))
    # PuzzleBoard, float image, some drops and duplicates.
    write(t, "puzzle_lattice_drops",
          lattice_header(0, 3, 0x12, 0, 30, 20, 18, -0.4) +
          lattice_corners(14, 10, 0.05,
                          lambda i, j: 0 if (i * 7 + j) % 11 == 0 else
                          (0x41 if (i + j) % 9 == 0 else 1)))
    # Lattice with raw doubles injected (mode 3), 16-bit image.
    body = lattice_header(1, 2, 0x20, 3, 60, 50, 15, 0.8)
    body += u16(7) + u16(5) + unit16(0.1)
    for j in range(6):
        for i in range(8):
            if (i + j) % 5 == 0:
                body += bytes([0x31]) + unit16(0.5) + unit16(0.5)
                for value in (float("nan"), 1e300, float("inf"), -0.0):
                    body += struct.pack("<d", value)
            else:
                body += bytes([1]) + unit16(0.5) + unit16(0.5)
    write(t, "lattice_raw_doubles", body)
    # Random points (mode 1).
    body = lattice_header(0, 1, 0x00, 1, 0, 0, 10, 0) + u16(60)
    for k in range(60):
        body += unit16((k * 37 % 101) / 101.0) + unit16((k * 53 % 97) / 97.0)
        body += unit16((k * 29 % 89) / 89.0) + unit16(0.5)
    write(t, "random_points", body)
    # Raw doubles only (mode 2): duplicates, NaN, huge.
    body = lattice_header(2, 0, 0x00, 2, 0, 0, 10, 0) + u16(6)
    for x, y in ((1.0, 2.0), (1.0, 2.0), (float("nan"), 3.0), (1e308, -1e308),
                 (5.0, float("-inf")), (10.0, 10.0)):
        body += struct.pack("<dddd", x, y, 0.3, 1.0)
    write(t, "raw_doubles", body)


if __name__ == "__main__":
    detect_seeds()
    grid_decode_seeds()
