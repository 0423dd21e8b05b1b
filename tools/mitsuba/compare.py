#!/usr/bin/env python3
"""Compares two float images (PFM or EXR), e.g. a vkray render against a Mitsuba one.

  PY=$(tools/mitsuba/setup | tail -n1)
  $PY tools/mitsuba/compare.py vkray.pfm mitsuba.pfm [--png side.png] [--heatmap] [--exposure E] [--json]
      [--blocks B [--block-png z.png]]

Prints per-channel means of both, the relative difference of the means (b/a - 1), the RMSE and the
mean relative difference of pixels whose mean is above 1e-3 (a: the reference). --png writes a,
b side by side (sRGB, clamped, times 2^exposure), and with --heatmap a third panel: |a - b| summed
over channels, normalised by the 99th percentile (black 0 .. white). Needs only numpy; an EXR is
read through Mitsuba (scalar_rgb variant).

--blocks B asks whether a and b differ by more than their noise, for two renders of one scene by
independent Monte Carlo estimators (any spp each; noise independent from pixel to pixel: no
denoiser, no sample stream shared by neighbouring pixels; at a few spp the noise is too skewed by
rare bright paths for the figures below, so give each image a few hundred). Per channel and B x B
block (partial blocks at the right and bottom edges are left out), with d = a - b over its
n = B^2 pixels:
  t = mean(d) / sqrt(var(d) / n),   var: the sample variance of d within the block.
Where a and b have the same expected value in every pixel, var(d) / n estimates the variance of
mean(d) without bias even though the noise differs from pixel to pixel; the variance of a or b
alone would not, since it holds the image's own edges. Each t then follows Student's t with n - 1
degrees of freedom (for noise near normal; fireflies make t smaller, so the test is cautious), and:
  chi2_per_block   mean of t^2 over the blocks, expected nu / (nu - 2) (1.033 for 8 x 8)
  excess_sigma     (sum t^2 - K nu/(nu-2)) / sqrt(K var(t^2)) over the K blocks: beyond about 3,
                   the difference has structure beyond noise (a lobe too wide, a caustic missing)
  mean_sigma       the whole image's mean(d) in units of its standard error (from the blocks):
                   beyond about 3, the means differ by more than noise (energy gained or lost)
  frac_abs_t_gt_3  the share of blocks with |t| > 3 (0.4% expected for 8 x 8), and `worst`: the
                   blocks of largest |t| (x, y of their top-left pixel, channel, t)
Blocks where d is constant are left out of the sums: counted as `exact_blocks` when d is 0 there
(both black, say) and as `constant_diff_blocks` when it is not (a difference without noise, which
always matters); blocks with a non-finite pixel are left out without a count. With --json all this
is a "blocks" entry of the JSON line. --block-png writes the blocks' t, summed over channels over
sqrt(3), as a map (B pixels a block; red: a brighter, blue: b brighter, full at |t| = 4; grey:
left out).
"""
import argparse
import json
import math
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


def block_test(a, b, size, worst=10):
    """The noise-normalised block comparison of --blocks (the docstring at the top): (statistics, t
    of shape (rows, cols, 3), NaN where a block is left out)."""
    rows, cols = a.shape[0] // size, a.shape[1] // size
    if rows == 0 or cols == 0:
        raise ValueError(f"--blocks {size}: the image ({a.shape[1]}x{a.shape[0]}) holds no whole block")
    n = size * size
    d = (a - b)[:rows * size, :cols * size].reshape(rows, size, cols, size, 3)
    d = d.transpose(0, 2, 4, 1, 3).reshape(rows, cols, 3, n)  # (block row, block column, channel, pixel)
    mean = d.mean(axis=3)
    var = d.var(axis=3, ddof=1)
    noisy = var > 0
    t = np.full(mean.shape, np.nan)
    t[noisy] = mean[noisy] / np.sqrt(var[noisy] / n)
    nu = n - 1
    expect = nu / (nu - 2) if nu > 2 else float("nan")  # E[t^2] and Var[t^2] under Student's t
    spread = 2 * nu * nu * (nu - 1) / ((nu - 2) ** 2 * (nu - 4)) if nu > 4 else float("nan")
    stats = {"block": size, "blocks_per_channel": rows * cols, "dof_per_block": nu,
             "expected_chi2_per_block": round(expect, 6)}
    per_channel = []
    for c in range(3):
        used = noisy[:, :, c]
        tc = t[:, :, c][used]
        k = int(tc.size)
        chi2 = float(np.sum(tc * tc))
        mean_d = float(mean[:, :, c][used].mean()) if k else 0.0  # the mean of the blocks' means ...
        se = math.sqrt(float(np.sum(var[:, :, c][used])) / n) / max(k, 1)  # ... and its standard error
        per_channel.append({
            "blocks": k,
            "chi2_per_block": round(chi2 / k, 6) if k else None,
            "excess_sigma": round((chi2 - k * expect) / math.sqrt(k * spread), 3) if k else None,
            "mean_sigma": round(mean_d / se, 3) if k and se > 0 else None,
            "frac_abs_t_gt_3": round(float(np.mean(np.abs(tc) > 3)), 6) if k else None,
            "exact_blocks": int(np.sum(~used & (mean[:, :, c] == 0))),
            "constant_diff_blocks": int(np.sum(~used & np.isfinite(mean[:, :, c]) & (mean[:, :, c] != 0)))})
    stats["channels"] = per_channel
    order = np.argsort(-np.nan_to_num(np.abs(t), nan=-1.0), axis=None)[:worst]
    stats["worst"] = [{"x": int(i // 3 % cols) * size, "y": int(i // 3 // cols) * size, "channel": "RGB"[i % 3],
                       "t": round(float(t.flat[i]), 3)} for i in order if np.isfinite(t.flat[i])]
    return stats, t


def block_map(t, size):
    """RGB8 picture of the blocks' t (summed over channels / sqrt 3): red where a is brighter, blue
    where b is, full at |t| = 4, grey where a block is left out."""
    z = np.sum(np.nan_to_num(t), axis=2) / math.sqrt(3)
    left_out = np.all(np.isnan(t), axis=2)
    level = np.clip(np.abs(z) / 4.0, 0, 1)
    rgb = np.zeros(z.shape + (3,))
    rgb[..., 0] = np.where(z > 0, level, 0)
    rgb[..., 2] = np.where(z < 0, level, 0)
    rgb[left_out] = 0.5
    rgb8 = (rgb * 255).round().astype(np.uint8)
    return np.repeat(np.repeat(rgb8, size, axis=0), size, axis=1)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("a", help="reference image (e.g. vkray's)")
    ap.add_argument("b", help="image to compare (e.g. Mitsuba's)")
    ap.add_argument("--png", help="write a side-by-side PNG here")
    ap.add_argument("--heatmap", action="store_true", help="add a panel with |a - b|")
    ap.add_argument("--exposure", type=float, default=0.0, help="scale the PNG panels by 2^E")
    ap.add_argument("--json", action="store_true", help="print one JSON line instead of text")
    ap.add_argument("--blocks", type=int, metavar="B", help="test a - b against noise over B x B blocks (8 is usual)")
    ap.add_argument("--block-png", help="with --blocks: write the blocks' t as a map here")
    ap.add_argument("--rows", metavar="Y0:Y1", help="compare only rows Y0 to Y1 - 1 (from the top; either may be left "
                    "out): e.g. the part of an image below an environment map's horizon, whose pixels the two renderers "
                    "interpolate differently (vkray: constant over a texel; Mitsuba: bilinear), a difference without noise")
    args = ap.parse_args(argv)
    if args.blocks is not None and args.blocks < 3:
        ap.error("--blocks: expected at least 3 (a block's variance needs its pixels)")
    if args.block_png and args.blocks is None:
        ap.error("--block-png needs --blocks")

    a, b = read_image(args.a), read_image(args.b)
    if a.shape != b.shape:
        sys.exit(f"compare: the images differ in size: {a.shape[1]}x{a.shape[0]} and {b.shape[1]}x{b.shape[0]}")
    if args.rows:
        try:
            y0, y1 = (int(v) if v else None for v in args.rows.split(":"))
        except ValueError:
            ap.error(f"--rows: expected Y0:Y1, got {args.rows!r}")
        a, b = a[y0:y1], b[y0:y1]
        if a.shape[0] == 0:
            ap.error(f"--rows {args.rows}: no rows left")
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
    if args.blocks is not None:
        try:
            result["blocks"], t = block_test(a, b, args.blocks)
        except ValueError as e:
            ap.error(str(e))
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
        if args.blocks is not None:
            bl = result["blocks"]
            ch = bl["channels"]

            def row(key):
                return " ".join("-" if c[key] is None else f"{c[key]:g}" for c in ch)

            print(f"blocks             {args.blocks}x{args.blocks}, {bl['blocks_per_channel']} a channel;"
                  f" t^2 expected {bl['expected_chi2_per_block']:g} a block")
            print(f"chi2 per block     {row('chi2_per_block')}")
            print(f"excess (sigma)     {row('excess_sigma')}   (beyond ~3: structure beyond noise)")
            print(f"mean diff (sigma)  {row('mean_sigma')}   (beyond ~3: the means differ beyond noise)")
            print(f"share |t| > 3      {row('frac_abs_t_gt_3')}")
            if any(c["constant_diff_blocks"] for c in ch):
                print(f"noiseless diffs    {row('constant_diff_blocks')} blocks differ by a constant")
            print("worst blocks       " + ", ".join(f"({w['x']},{w['y']}) {w['channel']} {w['t']:+g}" for w in bl["worst"][:5]))

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
    if args.block_png:
        write_png(args.block_png, block_map(t, args.blocks))
    return 0


if __name__ == "__main__":
    sys.exit(main())
