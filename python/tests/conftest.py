"""Shared fixtures: the module, the `emaki` binary, and the StyLit example at reduced size.

Run with Debian's Python and the build's module:
    PYTHONPATH=build/release/python /usr/bin/python3 -m pytest python/tests -q
"""

import os
import pathlib
import subprocess

import numpy as np
import pytest

import emaki

ROOT = pathlib.Path(__file__).resolve().parents[2]
STYLIT = ROOT / "tests" / "data" / "stylit"
GUIDES = ["fullgi", "dirdif", "dirspc", "indirb"]


def emaki_binary():
    path = os.environ.get("EMAKI_BINARY", str(ROOT / "build" / "release" / "apps" / "emaki" / "emaki"))
    if not os.path.exists(path):
        pytest.skip("no emaki binary at %s (set EMAKI_BINARY)" % path)
    return path


def run_cli(*args):
    """Runs the emaki binary; returns its stderr, failing the test when it fails."""
    proc = subprocess.run([emaki_binary(), *map(str, args)], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    return proc.stderr


def box_down(a, f):
    """Box-filters an HxWxC uint8 image down by f (H and W divisible by f), rounding."""
    h, w, c = a.shape
    m = a.reshape(h // f, f, w // f, f, c).astype(np.float64).mean(axis=(1, 3))
    return np.floor(m + 0.5).astype(np.uint8)


@pytest.fixture(scope="session")
def stylit_small(tmp_path_factory):
    """StyLit at a quarter of its size (300x228): the arrays and the PNG files holding them."""
    folder = tmp_path_factory.mktemp("stylit_small")
    files = {"style": folder / "source_style.png"}
    arrays = {"style": box_down(emaki.read_image(STYLIT / "source_style.png"), 4)}
    for name in GUIDES:
        for side in ("source", "target"):
            key = "%s_%s" % (side, name)
            arrays[key] = box_down(emaki.read_image(STYLIT / ("%s.png" % key)), 4)
            files[key] = folder / ("%s.png" % key)
    for key, path in files.items():
        emaki.write_image(path, arrays[key])
    # The PNG files hold exactly the arrays.
    for key, path in files.items():
        assert np.array_equal(emaki.read_image(path), arrays[key])
    return {"arrays": arrays, "files": files, "folder": folder}


def guides_of(data, kind, weight=0.5):
    d = data[kind]
    return [(d["source_" + n], d["target_" + n], weight) for n in GUIDES]


def cli_guide_args(files, weight=0.5):
    out = []
    for n in GUIDES:
        out += ["-guide", files["source_" + n], files["target_" + n], "-weight", str(weight)]
    return out
