"""emaki.read_image / write_image / image_channels: dtypes kept, EXR channels by name, one
array convention (HxW for one channel, HxWxC otherwise) shared with render() and synthesize()."""

import numpy as np
import pytest

import emaki


def test_png_round_trips_in_the_arrays_dtype(tmp_path):
    rng = np.random.default_rng(1)
    u8 = rng.integers(0, 256, (20, 30, 3), dtype=np.uint8)
    u16 = rng.integers(0, 65536, (20, 30, 4), dtype=np.uint16)
    gray = rng.integers(0, 256, (20, 30), dtype=np.uint8)
    emaki.write_image(tmp_path / "a.png", u8)
    emaki.write_image(str(tmp_path / "b.png"), u16)
    emaki.write_image(tmp_path / "c.png", gray)
    assert np.array_equal(emaki.read_image(tmp_path / "a.png"), u8)
    assert np.array_equal(emaki.read_image(tmp_path / "b.png"), u16)
    back = emaki.read_image(tmp_path / "c.png")
    assert back.shape == (20, 30) and np.array_equal(back, gray)
    emaki.write_image(tmp_path / "d.png", u16, depth=8)
    assert emaki.read_image(tmp_path / "d.png").dtype == np.uint8


def test_exr_channels_by_name(tmp_path):
    rng = np.random.default_rng(2)
    passes = rng.random((12, 16, 4), dtype=np.float32) * 10 - 5
    names = ["normal.X", "normal.Y", "normal.Z", "depth.Y"]
    emaki.write_image(tmp_path / "p.exr", passes, channels=names)
    in_file = emaki.image_channels(tmp_path / "p.exr")  # EXR keeps channels sorted by name
    assert sorted(in_file) == sorted(names)
    full = emaki.read_image(tmp_path / "p.exr")
    order = [names.index(n) for n in in_file]
    assert full.dtype == np.float32 and np.array_equal(full, passes[:, :, order])
    depth_normal = emaki.read_image(tmp_path / "p.exr", channels=["depth.Y", "normal.X"])
    assert np.array_equal(depth_normal, passes[:, :, [3, 0]])
    emaki.write_image(tmp_path / "h.exr", passes, channels=names, depth="half")
    assert np.allclose(emaki.read_image(tmp_path / "h.exr"), passes[:, :, order], atol=5e-3)
    depth = emaki.read_image(tmp_path / "p.exr", channels=["depth.Y"])
    assert depth.shape == (12, 16) and np.array_equal(depth, passes[:, :, 3])
    with pytest.raises(emaki.FileError, match="normal.W"):
        emaki.read_image(tmp_path / "p.exr", channels=["normal.W"])


def test_write_errors_name_the_argument(tmp_path):
    a = np.zeros((4, 5, 3), np.float32)
    with pytest.raises(emaki.InputError) as e:
        emaki.write_image(tmp_path / "x.exr", a, channels=["R", "G"])
    assert e.value.subject == "channels"
    with pytest.raises(emaki.InputError) as e:
        emaki.write_image(tmp_path / "x.exr", a, depth="12")
    assert e.value.subject == "depth"
    with pytest.raises(emaki.InputError) as e:
        emaki.write_image(tmp_path / "x.png", a.astype(np.float64))
    assert e.value.subject == "image"
    with pytest.raises(emaki.FileError):
        emaki.write_image(tmp_path / "x.bmp", a)


def test_one_channel_is_hxw_in_every_function(tmp_path):
    """A one-channel image has one shape whichever function made it, and goes back in as is."""
    passes = emaki.template((16, 12), aa=1, threads=1)
    emaki.write_image(tmp_path / "diffuse.exr", passes["diffuse"], channels=["diffuse.Y"])
    from_file = emaki.read_image(tmp_path / "diffuse.exr")
    assert passes["diffuse"].shape == from_file.shape == (12, 16)
    assert np.array_equal(passes["diffuse"], from_file)
    style = np.random.default_rng(3).random((12, 16), dtype=np.float32)
    out = emaki.synthesize(style, [(from_file, from_file)], pyramid_levels=1, threads=1)
    assert out.shape == style.shape
    emaki.write_image(tmp_path / "out.exr", out)
    assert emaki.read_image(tmp_path / "out.exr").shape == (12, 16)
