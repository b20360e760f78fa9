#!/usr/bin/env python3
"""A pen-hatching exemplar drawn by a program over emaki's own reference sphere.

Runs `emaki template` for the sphere's passes (the shot's light, elevation and field of view), then
draws ink strokes from them:

- on the sphere, strokes follow the shading: the first layer runs along the lines of equal
  N.L (they wrap around the form, away from the light), a second and a third cross it where the
  sphere turns darker; each stroke tapers at its ends and overshoots the contour by a few pixels
  where it runs off the sphere, as a hand-drawn hatch does;
- on the ground, the cast shadow is hatched with straight diagonal strokes, crossed where it is
  darkest; the lit ground and the background stay paper white.

The result is a grey PNG (white paper, dark strokes) with the sphere where `emaki template` put
it: a `kind = "matcap"` exemplar with `sphere = [W/2, H/2, 0.3 H]` and the same light, elevation,
fov and softness. Deterministic for a given --seed. Only numpy and the standard library.

    tools/hatching/make_hatching.py --emaki build/release/apps/emaki/emaki \\
        --out examples/town/hatching.png
"""

import argparse
import os
import struct
import subprocess
import tempfile
import zlib

import numpy as np


# ---------------------------------------------------------------------------------------------
# PNG in and out (8-bit, non-interlaced), enough for emaki's previews and a grey result (also
# used by bench/eval_data.py)


def read_png(path):
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", path
    pos, idat, width = 8, b"", 0
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
            assert depth == 8 and interlace == 0, f"{path}: only 8-bit non-interlaced PNG"
            channels = {0: 1, 2: 3, 4: 2, 6: 4}[colour]
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    stride = width * channels
    out = bytearray(height * stride)
    prev = bytearray(stride)
    for y in range(height):
        f = raw[y * (stride + 1)]
        row = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        if f == 2:
            row = bytearray((r + b) & 255 for r, b in zip(row, prev))
        elif f in (1, 3, 4):
            for x in range(stride):
                a = row[x - channels] if x >= channels else 0
                b = prev[x]
                if f == 1:
                    p = a
                elif f == 3:
                    p = (a + b) >> 1
                else:
                    c = prev[x - channels] if x >= channels else 0
                    pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                    p = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                row[x] = (row[x] + p) & 255
        out[y * stride:(y + 1) * stride] = row
        prev = row
    img = np.frombuffer(bytes(out), np.uint8).reshape(height, width, channels)
    return img.astype(np.float64) / 255.0


def write_png(path, img, level=9):
    """img float in [0, 1]: HxW (grey) or HxWx3 (RGB); filter 0, zlib `level`."""
    h, w = img.shape[:2]
    colour = 0 if img.ndim == 2 else 2
    rows = np.clip(np.round(img * 255.0), 0, 255).astype(np.uint8).reshape(h, -1)
    raw = b"".join(b"\x00" + rows[y].tobytes() for y in range(h))

    def chunk(kind, body):
        return (struct.pack(">I", len(body)) + kind + body +
                struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF))

    png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, colour, 0, 0, 0)) +
           chunk(b"IDAT", zlib.compress(raw, level)) + chunk(b"IEND", b""))
    with open(path, "wb") as f:
        f.write(png)


def srgb_decode(v):
    return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)


def box_blur(img, r):
    """Separable box filter of radius r (edge-clamped), applied twice: close to a Gaussian."""
    for _ in range(2):
        for axis in (0, 1):
            pad = [(0, 0)] * img.ndim
            pad[axis] = (r, r)
            p = np.pad(img, pad, mode="edge")
            c = np.cumsum(p, axis=axis)
            c = np.concatenate([np.zeros_like(np.take(c, [0], axis=axis)), c], axis=axis)
            n = img.shape[axis]
            img = (np.take(c, np.arange(2 * r + 1, n + 2 * r + 1), axis=axis) -
                   np.take(c, np.arange(0, n), axis=axis)) / (2 * r + 1)
    return img


# ---------------------------------------------------------------------------------------------
# The reference sphere's passes


def reference_passes(emaki, size, light, softness, elevation, fov):
    tmp = tempfile.mkdtemp(prefix="emaki_hatching_")
    subprocess.run([emaki, "template", "--out", tmp, "--size", f"{size[0]}x{size[1]}",
                    "--light", ",".join(str(v) for v in light), "--softness", str(softness),
                    "--elevation", str(elevation), "--fov", str(fov), "--aa", "3", "--previews"],
                   check=True)
    prev = os.path.join(tmp, "preview")
    p = {name: read_png(os.path.join(prev, f"reference_{name}.png"))
         for name in ("alpha", "normal", "diffuse", "shadow", "object_id")}
    alpha = srgb_decode(p["alpha"][..., 0])
    normal = p["normal"] * 2.0 - 1.0
    # Ids are shown as hashed colours: the sphere's is the one at the image centre.
    h, w = alpha.shape
    ids = p["object_id"]
    sphere = (np.abs(ids - ids[h // 2, w // 2]).sum(axis=2) < 0.02) & (alpha > 0.5)
    ground = (alpha > 0.5) & ~sphere
    return dict(sphere=sphere, ground=ground, normal=normal,
                diffuse=srgb_decode(p["diffuse"][..., 0]),
                shadow=srgb_decode(p["shadow"][..., 0]))


# ---------------------------------------------------------------------------------------------
# Strokes


def unit(v):
    n = np.sqrt((v ** 2).sum(axis=-1, keepdims=True))
    return v / np.maximum(n, 1e-9)


def rotate(d, deg):
    a = np.radians(deg)
    c, s = np.cos(a), np.sin(a)
    return np.stack([c * d[..., 0] - s * d[..., 1], s * d[..., 0] + c * d[..., 1]], axis=-1)


def fields(ps, light):
    """Darkness in [0, 1] and the stroke direction (x right, y down) of each hatching layer."""
    h, w = ps["sphere"].shape
    L = np.asarray(light, np.float64)
    L = L / np.linalg.norm(L)
    ndl = box_blur((ps["normal"] * L).sum(axis=2), 3)
    gy, gx = np.gradient(ndl)
    # Image y points down, camera y up: the gradient is taken in image axes already.
    grad = unit(box_blur(np.stack([gx, gy], axis=-1), 4))
    along = np.stack([-grad[..., 1], grad[..., 0]], axis=-1)  # along the lines of equal N.L
    dark = np.zeros((h, w))
    # Tone from N.L, not the clamped diffuse: the side turned from the light darkens on towards
    # the far side instead of being uniformly black.
    dark[ps["sphere"]] = np.clip((0.8 - ndl[ps["sphere"]]) / 1.5, 0, 1)
    dark[ps["ground"]] = 0.7 * ps["shadow"][ps["ground"]]
    ground_dir = unit(np.array([1.0, -0.45]))
    layers = []
    for k, (threshold, sphere_turn, ground_turn) in enumerate(
            [(0.12, 0.0, 0.0), (0.45, 60.0, 70.0), (0.78, -60.0, -45.0)]):
        d = np.where(ps["sphere"][..., None], rotate(along, sphere_turn),
                     np.broadcast_to(rotate(ground_dir, ground_turn), (h, w, 2)))
        layers.append((threshold, d))
    return dark, layers


def trace(seeds, direction, region, dark, threshold, lengths, overshoot, step=0.6):
    """Stroke points from each seed both ways along `direction`, within `region` and where
    `dark` >= threshold; past either edge a stroke runs on straight for its overshoot."""
    h, w = region.shape
    points, weights = [], []
    n = len(seeds)
    half = lengths / 2.0
    for sign in (1.0, -1.0):
        p = seeds.copy()
        d0 = direction[p[:, 1].astype(int), p[:, 0].astype(int)] * sign
        d = d0.copy()
        travelled = np.zeros(n)
        past_edge = np.full(n, -1.0)  # distance travelled when the stroke left its region
        alive = np.ones(n, bool)
        while alive.any():
            xi = np.clip(p[:, 0].astype(int), 0, w - 1)
            yi = np.clip(p[:, 1].astype(int), 0, h - 1)
            inside = region[yi, xi] & (dark[yi, xi] >= threshold - 0.04)
            leaving = alive & ~inside & (past_edge < 0)
            past_edge[leaving] = travelled[leaving]
            following = alive & (past_edge < 0)
            nd = direction[yi, xi]
            nd = np.where((nd * d).sum(axis=1, keepdims=True) < 0, -nd, nd)
            d[following] = unit(0.7 * d[following] + 0.3 * nd[following])
            u = travelled / half
            taper = np.sqrt(np.clip(1.0 - u, 0, 1)) * np.minimum(1.0, 0.35 + 2.0 * (1.0 - u))
            points.append(p[alive].copy())
            weights.append(taper[alive])
            p = p + step * d
            travelled += step
            alive &= travelled < half
            alive &= ~((past_edge >= 0) & (travelled - past_edge > overshoot))
            alive &= (p[:, 0] >= 0) & (p[:, 0] < w - 1) & (p[:, 1] >= 0) & (p[:, 1] < h - 1)
    return np.concatenate(points), np.concatenate(weights)


def splat(shape, points, weights, width):
    """Coverage of round pens of `width` pixels at the points, on a 2x supersampled canvas."""
    h, w = shape
    canvas = np.zeros((2 * h, 2 * w))
    r = width  # in canvas pixels (half the width at 2x)
    offsets = [(dx, dy) for dy in range(-2, 3) for dx in range(-2, 3) if dx * dx + dy * dy <= r * r]
    cx, cy = np.round(points[:, 0] * 2).astype(int), np.round(points[:, 1] * 2).astype(int)
    for dx, dy in offsets:
        x, y = np.clip(cx + dx, 0, 2 * w - 1), np.clip(cy + dy, 0, 2 * h - 1)
        np.add.at(canvas, (y, x), weights)
    canvas = np.clip(canvas * 0.55, 0, 1)
    return canvas.reshape(h, 2, w, 2).mean(axis=(1, 3))


def hatch(ps, light, seed, spacing):
    rng = np.random.RandomState(seed)
    h, w = ps["sphere"].shape
    dark, layers = fields(ps, light)
    paper = np.ones((h, w))
    for k, (threshold, direction) in enumerate(layers):
        gy, gx = np.mgrid[0:h:spacing, 0:w:spacing].astype(np.float64)
        seeds = np.stack([gx.ravel(), gy.ravel()], axis=1)
        seeds += rng.uniform(0, spacing, seeds.shape)
        seeds[:, 0] = np.clip(seeds[:, 0], 0, w - 1)
        seeds[:, 1] = np.clip(seeds[:, 1], 0, h - 1)
        # One seed per `spacing` across the strokes and per stroke length along them.
        seeds = seeds[rng.uniform(0, 1, len(seeds)) < spacing / 26.0]
        xi, yi = seeds[:, 0].astype(int), seeds[:, 1].astype(int)
        for region in (ps["sphere"], ps["ground"]):
            keep = region[yi, xi] & (dark[yi, xi] >= threshold)
            s = seeds[keep]
            if len(s) == 0:
                continue
            lengths = rng.uniform(22, 40, len(s))
            overshoot = rng.uniform(2.0, 7.0, len(s))
            pts, wts = trace(s, direction, region, dark, threshold, lengths, overshoot)
            ink = splat((h, w), pts, wts, width=1.4)
            paper *= 1.0 - 0.88 * ink
    return paper


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--emaki", required=True, help="the emaki binary")
    ap.add_argument("--out", required=True, help="the PNG to write")
    ap.add_argument("--size", default="800x600")
    ap.add_argument("--light", default="0.3,0.9,-0.3", help="towards the key light, camera-relative")
    ap.add_argument("--softness", type=float, default=8.0)
    ap.add_argument("--elevation", type=float, default=15.0)
    ap.add_argument("--fov", type=float, default=30.0)
    ap.add_argument("--spacing", type=float, default=6.0, help="stroke spacing, pixels")
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    size = [int(v) for v in a.size.split("x")]
    light = [float(v) for v in a.light.split(",")]
    ps = reference_passes(a.emaki, size, light, a.softness, a.elevation, a.fov)
    write_png(a.out, hatch(ps, light, a.seed, a.spacing))
    print(f"wrote {a.out}: sphere = [{size[0] / 2}, {size[1] / 2}, {0.3 * size[1]}]")


if __name__ == "__main__":
    main()
