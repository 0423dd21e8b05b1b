#!/usr/bin/env python3
"""Compares two float images (PFM or EXR), e.g. a vkray render against a Mitsuba one.

  PY=$(tools/mitsuba/setup | tail -n1)
  $PY tools/mitsuba/compare.py vkray.pfm mitsuba.pfm [--png side.png] [--heatmap] [--exposure E] [--json]

Prints per-channel means of both, the relative difference of the means (b/a - 1), the RMSE and the
mean relative difference of pixels whose mean is above 1e-3 (a: the reference). --png writes a,
b side by side (sRGB, clamped, times 2^exposure), and with --heatmap a third panel: |a - b| summed
over channels, normalised by the 99th percentile (black 0 .. white). Needs only numpy; an EXR is
read through Mitsuba (scalar_rgb variant).
"""
import argparse
import json
import struct
import sys
import zlib

import numpy as np


def read_pfm(path):
    with open(path, "rb") as f:
        data = f.read()
    parts, pos = [], 0
    while len(parts) < 4:  # "PF" w h scale, separated by whitespace
        while data[pos:pos + 1].isspace():
            pos += 1
        end = pos
        while not data[end:end + 1].isspace():
            end += 1
        parts.append(data[pos:end].decode("ascii"))
        pos = end
    pos += 1  # the single whitespace character after the scale
    kind, w, h, scale = parts[0], int(parts[1]), int(parts[2]), float(parts[3])
    channels = {"PF": 3, "Pf": 1}[kind]
    dtype = "<f4" if scale < 0 else ">f4"
    img = np.frombuffer(data, dtype=dtype, count=w * h * channels, offset=pos).reshape(h, w, channels)
    img = img[::-1].astype(np.float64)  # stored bottom row first
    return np.repeat(img, 3, axis=2) if channels == 1 else img


def read_image(path):
    if path.lower().endswith(".pfm"):
        return read_pfm(path)
    import mitsuba as mi
    mi.set_variant("scalar_rgb")
    bmp = mi.Bitmap(path).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, srgb_gamma=False)
    return np.array(bmp, dtype=np.float64)


def write_png(path, rgb8):
    h, w, _ = rgb8.shape
    raw = b"".join(b"\x00" + rgb8[y].tobytes() for y in range(h))

    def chunk(tag, body):
        return struct.pack(">I", len(body)) + tag + body + struct.pack(">I", zlib.crc32(tag + body) & 0xFFFFFFFF)

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))


def to_srgb8(linear):
    c = np.clip(linear, 0.0, 1.0)
    s = np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1 / 2.4) - 0.055)
    return np.round(255.0 * s).astype(np.uint8)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("a", help="reference image (e.g. vkray's)")
    ap.add_argument("b", help="image to compare (e.g. Mitsuba's)")
    ap.add_argument("--png", help="write a side-by-side PNG here")
    ap.add_argument("--heatmap", action="store_true", help="add a panel with |a - b|")
    ap.add_argument("--exposure", type=float, default=0.0, help="scale the PNG panels by 2^E")
    ap.add_argument("--json", action="store_true", help="print one JSON line instead of text")
    args = ap.parse_args(argv)

    a, b = read_image(args.a), read_image(args.b)
    if a.shape != b.shape:
        sys.exit(f"compare: the images differ in size: {a.shape[1]}x{a.shape[0]} and {b.shape[1]}x{b.shape[0]}")
    mean_a, mean_b = a.mean(axis=(0, 1)), b.mean(axis=(0, 1))
    rel_means = np.where(mean_a != 0, mean_b / np.where(mean_a != 0, mean_a, 1) - 1, 0.0)
    rmse = float(np.sqrt(np.mean((a - b) ** 2)))
    lum_a, lum_b = a.mean(axis=2), b.mean(axis=2)
    lit = lum_a > 1e-3
    rel_pixels = float(np.mean(np.abs(lum_b[lit] - lum_a[lit]) / lum_a[lit])) if lit.any() else 0.0
    result = {"a": args.a, "b": args.b, "width": a.shape[1], "height": a.shape[0],
              "mean_a": mean_a.round(6).tolist(), "mean_b": mean_b.round(6).tolist(),
              "rel_diff_of_means": rel_means.round(6).tolist(), "rmse": round(rmse, 6),
              "mean_rel_pixel_diff": round(rel_pixels, 6), "non_finite_a": int((~np.isfinite(a)).sum()),
              "non_finite_b": int((~np.isfinite(b)).sum())}
    if args.json:
        print(json.dumps(result))
    else:
        print(f"size               {a.shape[1]}x{a.shape[0]}")
        print(f"mean a (R,G,B)     {' '.join(f'{x:.6f}' for x in mean_a)}   {args.a}")
        print(f"mean b (R,G,B)     {' '.join(f'{x:.6f}' for x in mean_b)}   {args.b}")
        print(f"b/a - 1 of means   {' '.join(f'{x:+.4%}' for x in rel_means)}")
        print(f"RMSE               {rmse:.6f}")
        print(f"mean |b-a|/a       {rel_pixels:.4%}  (pixels with mean(a) > 1e-3)")
        if result["non_finite_a"] or result["non_finite_b"]:
            print(f"non-finite values  a: {result['non_finite_a']}, b: {result['non_finite_b']}")

    if args.png:
        gain = 2.0 ** args.exposure
        panels = [to_srgb8(a * gain), to_srgb8(b * gain)]
        if args.heatmap:
            diff = np.abs(a - b).sum(axis=2)
            top = np.percentile(diff, 99) or 1.0
            panels.append(np.repeat((np.clip(diff / top, 0, 1) * 255).round().astype(np.uint8)[:, :, None], 3, axis=2))
        gap = np.full((a.shape[0], 4, 3), 128, np.uint8)
        row = [panels[0]]
        for p in panels[1:]:
            row += [gap, p]
        write_png(args.png, np.concatenate(row, axis=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
