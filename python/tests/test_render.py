"""emaki.render and emaki.template give the passes `emaki render` / `emaki template` write,
bit for bit (float EXR)."""

import numpy as np
import pytest

import emaki
from conftest import ROOT, run_cli

FOX = ROOT / "tests" / "data" / "scenes" / "Fox.glb"


def assert_same_passes(passes, exr):
    assert sorted(passes) == sorted(emaki.pass_names)
    assert sorted(emaki.image_channels(exr)) == sorted(sum(emaki.pass_channels.values(), []))
    for name, array in passes.items():
        from_file = emaki.read_image(exr, channels=emaki.pass_channels[name])
        assert array.dtype == np.float32 and array.shape == from_file.shape, name
        assert np.array_equal(array, from_file), name


def test_render_matches_emaki_render(tmp_path):
    run_cli("render", FOX, "--frames", "3", "--size", "64x36", "--clip", "Walk", "--float",
            "--quiet", "--out", tmp_path)
    passes = emaki.render(FOX, 3, (64, 36), clip="Walk")
    assert passes["normal"].shape == (36, 64, 3) and passes["depth"].shape == (36, 64)
    assert_same_passes(passes, tmp_path / "frame_0003.exr")


def test_template_matches_emaki_template(tmp_path):
    run_cli("template", "--size", "80x60", "--sphere", "40,32,18", "--elevation", "20",
            "--float", "--out", tmp_path)
    passes = emaki.template((80, 60), sphere=(40, 32, 18), elevation=20)
    paint = passes.pop("template")
    assert_same_passes(passes, tmp_path / "reference.exr")
    emaki.write_image(tmp_path / "mine.png", paint, depth=8)
    assert np.array_equal(emaki.read_image(tmp_path / "mine.png"),
                          emaki.read_image(tmp_path / "template.png"))


def test_render_errors_name_the_argument(tmp_path):
    with pytest.raises(emaki.InputError) as e:
        emaki.render(FOX, 0, (64, 36), clip="Dance")
    assert e.value.subject == "clip" and "Walk" in e.value.message
    with pytest.raises(emaki.InputError) as e:
        emaki.render(FOX, 0, (64, 36), gltf_camera=0)
    assert e.value.subject == "gltf_camera"
    with pytest.raises(emaki.InputError) as e:
        emaki.render(FOX, 100000, (64, 36), clip="Walk")
    assert e.value.subject == "frame"
    with pytest.raises(emaki.InputError) as e:
        emaki.render(FOX, 0, (0, 36))
    assert e.value.subject == "size"
    with pytest.raises(emaki.InputError) as e:
        emaki.render(FOX, 0, (64, 36), fov=float("nan"))
    assert e.value.subject == "fov"
    with pytest.raises(emaki.FileError) as e:
        emaki.render(tmp_path / "none.glb", 0, (64, 36))
    assert e.value.filename == str(tmp_path / "none.glb")
    with pytest.raises(emaki.InputError) as e:
        emaki.template((80, 60), sphere=(40, 32, 5000))
    assert e.value.subject == "sphere"
