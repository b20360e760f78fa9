"""The data of the evaluation set (bench/eval_set.py): guides rendered by emaki, MatCaps and
papers converted by oiiotool, and exemplars drawn by a program (marked `generated` in the set).

Everything is written under one folder and is deterministic for a given emaki build: the
generators use fixed seeds. Only numpy, the standard library, emaki and oiiotool.
"""

import os
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "tools",
                                "hatching"))
import make_hatching as H  # noqa: E402  (its PNG writer, sRGB decode and box blur)

LIGHT = "0.5,0.6,0.6"  # camera-relative key light: from the upper right, in front, so the
# sphere shows its whole tonal range


def run(cmd):
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)


def read_image(path, tmp_dir):
    """Any image oiiotool reads, as float RGB in [0, 1] (through a binary PPM)."""
    ppm = os.path.join(tmp_dir, "read.ppm")
    try:
        run(["oiiotool", path, "--ch", "R,G,B", "-d", "uint8", "-o", ppm])
    except subprocess.CalledProcessError:  # one channel
        run(["oiiotool", path, "--ch", "Y,Y,Y", "-d", "uint8", "-o", ppm])
    data = open(ppm, "rb").read()
    parts = data.split(maxsplit=4)
    w, h = int(parts[1]), int(parts[2])
    img = np.frombuffer(parts[4][:w * h * 3], np.uint8).reshape(h, w, 3)
    return img.astype(np.float64) / 255.0


def write_png(path, img):
    """8-bit RGB PNG, img float in [0, 1], HxWx3 or HxW (grey, written as RGB)."""
    if img.ndim == 2:
        img = np.repeat(img[..., None], 3, axis=2)
    H.write_png(path, img, level=6)


srgb_decode = H.srgb_decode


def blur(img, r):
    """make_hatching's box blur (twice, close to a Gaussian) at radius r, at least 1."""
    return H.box_blur(img, max(1, int(r)))


def smooth_noise(shape, scale, rng):
    return blur(rng.random(shape), scale)


def normalise(v):
    lo, hi = np.percentile(v, 1), np.percentile(v, 99)
    return np.clip((v - lo) / max(hi - lo, 1e-9), 0, 1)


# ---------------------------------------------------------------------------------------------
# Guides


def template(emaki, out_dir, w, h):
    """emaki's reference sphere: returns the preview folder (reference_<pass>.png)."""
    if not os.path.exists(os.path.join(out_dir, "preview", "reference_normal.png")):
        run([emaki, "template", "--out", out_dir, "--size", f"{w}x{h}", "--light", LIGHT,
             "--softness", "8", "--elevation", "15", "--aa", "3", "--previews"])
    return os.path.join(out_dir, "preview", "reference_")


def render(emaki, scene, out_dir, w, h, frame=0, clip=None):
    """One frame of a glTF scene: returns the preview prefix (frame_NNNN_<pass>.png)."""
    prefix = os.path.join(out_dir, "preview", f"frame_{frame:04d}_")
    if not os.path.exists(prefix + "normal.png"):
        cmd = [emaki, "render", scene, "--out", out_dir, "--size", f"{w}x{h}", "--frames",
               str(frame), "--light", LIGHT, "--previews", "--quiet"]
        if clip:
            cmd += ["--clip", clip]
        run(cmd)
    return prefix


def sphere_normal(path, size):
    """A MatCap's guide: the camera-space normal of a sphere filling the square image, in the
    previews' encoding (n * 0.5 + 0.5 on surfaces, black where there is none, as emaki's
    background)."""
    c = (np.arange(size) + 0.5) / size * 2.0 - 1.0
    x, y = np.meshgrid(c, -c)
    r2 = x * x + y * y
    inside = r2 < 1.0
    z = np.sqrt(np.clip(1.0 - r2, 0, 1))
    n = np.stack([x, y, z], axis=2) * inside[..., None]
    write_png(path, (n * 0.5 + 0.5) * inside[..., None])


def matcap(name, size, path, shared, tmp_dir):
    """A MatCap EXR resized, tone-mapped (clamped) and sRGB-encoded to a PNG exemplar."""
    run(["oiiotool", os.path.join(shared, "matcaps", name + ".exr"), "--resize",
         f"{size}x{size}", "--colorconvert", "linear", "sRGB", "-d", "uint8", "-o", path])


def paper(shared, name, w, h, tmp_dir):
    img = read_image(os.path.join(shared, "papers", name), tmp_dir)
    reps = (h // img.shape[0] + 1, w // img.shape[1] + 1, 1)
    return np.tile(img, reps)[:h, :w].mean(axis=2)


# ---------------------------------------------------------------------------------------------
# Generated exemplars over emaki's reference sphere (tone = shading; ground shadow included)


def sphere_tone(prefix, tmp_dir):
    """Darkness in [0, 1] on the sphere and in its cast shadow; 0 on lit ground / background."""
    diffuse = srgb_decode(read_image(prefix + "diffuse.png", tmp_dir)[..., 0])
    shadow = srgb_decode(read_image(prefix + "shadow.png", tmp_dir)[..., 0])
    alpha = srgb_decode(read_image(prefix + "alpha.png", tmp_dir)[..., 0])
    normal = read_image(prefix + "normal.png", tmp_dir) * 2.0 - 1.0
    h, w = diffuse.shape
    ids = read_image(prefix + "object_id.png", tmp_dir)
    sphere = (np.abs(ids - ids[h // 2, w // 2]).sum(axis=2) < 0.02) & (alpha > 0.5)
    tone = np.where(sphere, 1.0 - diffuse, 0.8 * shadow * (alpha > 0.5))
    return tone, sphere, normal


def stippling(prefix, path, tmp_dir, seed=3):
    """Ink dots on a jittered grid, placed where a random draw falls under the tone."""
    tone, _, _ = sphere_tone(prefix, tmp_dir)
    h, w = tone.shape
    rng = np.random.default_rng(seed)
    cell = 3.0
    gy, gx = np.mgrid[0:h:cell, 0:w:cell]
    py = gy + rng.random(gy.shape) * cell
    px = gx + rng.random(gx.shape) * cell
    t = tone[np.clip(py.astype(int), 0, h - 1), np.clip(px.astype(int), 0, w - 1)]
    keep = rng.random(t.shape) < t ** 1.3
    ink = np.zeros((h, w))
    yy, xx = np.mgrid[0:h, 0:w]
    for y, x, rad in zip(py[keep], px[keep], 0.7 + 0.6 * rng.random(keep.sum())):
        y0, y1, x0, x1 = int(y - 3), int(y + 4), int(x - 3), int(x + 4)
        sub = np.s_[max(y0, 0):min(y1, h), max(x0, 0):min(x1, w)]
        d = np.sqrt((yy[sub] + 0.5 - y) ** 2 + (xx[sub] + 0.5 - x) ** 2)
        ink[sub] = np.maximum(ink[sub], np.clip(rad + 0.5 - d, 0, 1))
    write_png(path, 0.97 - 0.9 * ink)


def dry_brush(prefix, path, shared, tmp_dir, seed=5):
    """Broken strokes of a dry brush: streaky bristle noise along a slanted direction, coverage
    growing with the tone, three paints, paper showing through the gaps."""
    tone, sphere, _ = sphere_tone(prefix, tmp_dir)
    h, w = tone.shape
    rng = np.random.default_rng(seed)
    # Bristle streaks: noise smeared along rows, then sheared 30 degrees.
    big = rng.random((h + w, w))
    streak = blur(blur(big, 1).T, 1).T
    streak = np.cumsum(streak - streak.mean(), axis=1)
    streak = streak - blur(streak, 20)
    yy, xx = np.mgrid[0:h, 0:w]
    streak = normalise(streak[(yy + (xx * 0.55).astype(int)) % (h + w), xx])
    lumpy = smooth_noise((h, w), 12, rng)
    cover = np.clip((tone * 1.25 + 0.3 * (lumpy - 0.5) - (1 - streak)) * 4.0, 0, 1)
    pap = paper(shared, "roughpaper.png", w, h, tmp_dir)
    base = np.array([0.93, 0.90, 0.82]) * (0.85 + 0.15 * pap[..., None])
    paint = np.where((tone > 0.55)[..., None], np.array([0.16, 0.18, 0.32]),
                     np.where((tone > 0.3)[..., None], np.array([0.55, 0.33, 0.22]),
                              np.array([0.86, 0.66, 0.35])))
    write_png(path, base * (1 - cover[..., None]) + paint * cover[..., None])


def watercolour(prefix, path, shared, tmp_dir, seed=7):
    """Washes: three glazes with wobbly, soft edges, darker where a wash pools at its border,
    pigment granulating in the paper's grain."""
    tone, _, _ = sphere_tone(prefix, tmp_dir)
    h, w = tone.shape
    s = max(h, w) / 512.0
    rng = np.random.default_rng(seed)
    pap = paper(shared, "canvas_01.png", w, h, tmp_dir)
    out = np.ones((h, w, 3)) * np.array([0.96, 0.94, 0.89])
    glazes = [(0.12, [0.35, 0.45, 0.75]), (0.4, [0.55, 0.25, 0.55]), (0.68, [0.2, 0.15, 0.35])]
    for level, colour in glazes:
        wobble = (smooth_noise((h, w), 18 * s, rng) - 0.5) * 0.6
        mask = blur(((tone + wobble) > level).astype(np.float64), 2 * s)
        edge = np.clip(mask - blur(mask, 6 * s), 0, 1) * 2.5
        density = 0.45 * mask * (0.75 + 0.5 * pap) + 0.5 * edge
        out = out * (1 - density[..., None] * (1 - np.array(colour)))
    write_png(path, np.clip(out, 0, 1))


def keyframe_painting(prefix, path, shared, tmp_dir, seed=11):
    """A key frame "painted" over a Fox render: albedo under three-tone shading, brush marks
    following the surface (noise smeared along the normal's screen direction), an ink outline,
    on paper."""
    albedo = read_image(prefix + "albedo.png", tmp_dir)
    diffuse = srgb_decode(read_image(prefix + "diffuse.png", tmp_dir)[..., 0])
    alpha = srgb_decode(read_image(prefix + "alpha.png", tmp_dir)[..., 0])
    # The outline preview is dark lines on white.
    ink = 1.0 - read_image(prefix + "outline.png", tmp_dir)[..., 0]
    normal = read_image(prefix + "normal.png", tmp_dir) * 2.0 - 1.0
    h, w = diffuse.shape
    s = max(h, w) / 512.0
    rng = np.random.default_rng(seed)
    shade = 0.35 + 0.65 * blur(np.round(diffuse * 2) / 2, 1.5 * s)
    marks = smooth_noise((h, w), 2 * s, rng) + 0.5 * normal[..., 0] * normal[..., 1]
    marks = normalise(marks + blur(rng.random((h, w)), 4 * s))
    pap = paper(shared, "pastelpaper_01.png", w, h, tmp_dir)
    col = albedo * shade[..., None] * (0.8 + 0.4 * marks[..., None])
    col = col * alpha[..., None] + (1 - alpha[..., None]) * np.array([0.92, 0.88, 0.8])
    col = col * (0.85 + 0.15 * pap[..., None])
    col = col * (1 - 0.85 * np.clip(ink * 1.5, 0, 1)[..., None])
    write_png(path, np.clip(col, 0, 1))
