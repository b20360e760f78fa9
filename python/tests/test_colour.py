"""emaki.convert_colorspace against OpenColorIO's own Python bindings (python3-pyopencolorio),
and the colour keys through Shot.from_dict."""

import pathlib

import numpy as np
import pytest

import emaki

ROOT = pathlib.Path(__file__).resolve().parents[2]
BUILTIN = ROOT / "src" / "colour" / "emaki.ocio"
BLENDER = pathlib.Path("/usr/share/blender/datafiles/colormanagement/config.ocio")


def patch():
    rng = np.random.default_rng(7)
    return rng.uniform(0.0, 1.0, size=(4, 5, 4)).astype(np.float32)


@pytest.fixture(autouse=True)
def no_ocio_env(monkeypatch):
    monkeypatch.delenv("OCIO", raising=False)


def ocio_reference(config_path, image, src, dst):
    ocio = pytest.importorskip("PyOpenColorIO")
    config = ocio.Config.CreateFromFile(str(config_path))
    cpu = config.getProcessor(src, dst).getDefaultCPUProcessor()
    rgb = np.ascontiguousarray(image[..., :3]).copy()
    cpu.applyRGB(rgb)
    return rgb


@pytest.mark.parametrize("src,dst", [("sRGB texture", "scene-linear Rec.709"),
                                     ("scene-linear Rec.709", "ACEScg"),
                                     ("ACEScg", "sRGB texture")])
def test_matches_opencolorio(src, dst):
    image = patch()
    out = emaki.convert_colorspace(image, src, dst)
    assert out.dtype == np.float32 and out.shape == image.shape
    np.testing.assert_allclose(out[..., :3], ocio_reference(BUILTIN, image, src, dst), atol=1e-4)
    np.testing.assert_array_equal(out[..., 3], image[..., 3])  # alpha kept


def test_roles_and_an_explicit_config():
    image = patch()
    a = emaki.convert_colorspace(image, "color_picking", "scene_linear")
    b = emaki.convert_colorspace(image, "sRGB texture", "scene-linear Rec.709", config=BUILTIN)
    np.testing.assert_array_equal(a, b)


def test_blender_config():
    if not BLENDER.exists():
        pytest.skip(f"{BLENDER} is not installed (Debian's blender package)")
    image = patch()
    out = emaki.convert_colorspace(image, "sRGB", "Linear", config=BLENDER)
    np.testing.assert_allclose(out[..., :3], ocio_reference(BLENDER, image, "sRGB", "Linear"),
                               atol=1e-4)


def test_unknown_space_names_the_argument_and_the_nearest():
    with pytest.raises(emaki.InputError) as e:
        emaki.convert_colorspace(patch(), "sRGB textur", "ACEScg")
    assert e.value.subject == "src"
    assert "nearest: 'sRGB texture'" in str(e.value)
    with pytest.raises(emaki.InputError) as e:
        emaki.convert_colorspace(patch(), "ACEScg", "acescc")
    assert e.value.subject == "dst"
    with pytest.raises(emaki.InputError):
        emaki.convert_colorspace(patch()[..., :2], "ACEScg", "raw")


def test_shot_keys_through_from_dict(tmp_path):
    data = ROOT / "tests" / "data"
    d = {
        "source": {"scene": str(data / "scenes" / "Fox.glb"), "frames": [0, 0], "size": [32, 24]},
        "exemplars": {"s": {"painting": str(data / "stylit" / "source_style.png"),
                            "colorspace": "sRGB texture"}},
        "layers": {"base": {"kind": "base", "exemplar": "s"}},
        "compositing": {"space": "scene_linear", "paper_colorspace": "ACEScg"},
        "outputs": {"folder": str(tmp_path / "out"), "view": "Filmic"},
    }
    emaki.Shot.from_dict(d)
    d["outputs"]["view"] = "Filmc"
    with pytest.raises(emaki.InputError) as e:
        emaki.Shot.from_dict(d)
    assert e.value.subject == "outputs.view"
    assert "nearest: 'Filmic'" in str(e.value)
