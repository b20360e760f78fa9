"""Bad input raises emaki.InputError (a ValueError) or emaki.FileError (an OSError) naming the
argument or file: wrong dtype, shape, size mismatch, NaN, parameters out of range."""

import math

import numpy as np
import pytest

import emaki


def noise(shape, seed=1, dtype=np.float32):
    return np.random.default_rng(seed).random(shape, dtype=np.float32).astype(dtype)


STYLE = noise((40, 48, 3), 1)
SRC = noise((40, 48, 3), 2)
TGT = noise((36, 44, 3), 3)


def error_of(*args, **kwargs):
    with pytest.raises(emaki.InputError) as e:
        emaki.synthesize(*args, **kwargs)
    assert isinstance(e.value, ValueError) and isinstance(e.value, emaki.Error)
    assert str(e.value).startswith(e.value.subject + ": ")
    assert str(e.value) == e.value.subject + ": " + e.value.message
    return e.value


def test_wrong_dtype_names_the_argument_and_the_dtype():
    e = error_of(STYLE.astype(np.float64), [(SRC, TGT)])
    assert e.subject == "style" and "float64" in e.message and "uint8, uint16 or float32" in e.message
    e = error_of(STYLE, [(SRC, TGT.astype(np.int32))])
    assert e.subject == "guides[0][1]" and "int32" in e.message
    e = error_of(STYLE, [(SRC, TGT)], np.ones((36, 44), bool))
    assert e.subject == "mask" and "bool" in e.message
    e = error_of(STYLE.tolist(), [(SRC, TGT)])
    assert e.subject == "style" and "numpy array" in e.message


def test_wrong_shape():
    assert "HxW or HxWxC" in error_of(STYLE.ravel(), [(SRC, TGT)]).message
    assert error_of(STYLE, [(SRC[None], TGT)]).subject == "guides[0][0]"
    e = error_of(noise((40, 48, 5)), [(SRC, TGT)])
    assert e.subject == "style" and "1 to 4 channels" in e.message
    assert error_of(STYLE[:0], [(SRC, TGT)]).message.startswith("is empty")


def test_size_mismatches_name_the_image():
    e = error_of(STYLE, [(SRC[:, :40], TGT)])
    assert e.subject == "guides[0][0]" and "source guide is 40x40 but the style 'style' is 48x40" in e.message
    e = error_of(STYLE, [(SRC, TGT), (SRC, TGT[:30])])
    assert e.subject == "guides[1][1]" and "target guide is 44x30 but 'guides[0][1]' is 44x36" in e.message
    e = error_of(STYLE, [(SRC, TGT)], np.ones((30, 44), np.uint8))
    assert e.subject == "mask" and "mask is 44x30 but the target is 44x36" in e.message


@pytest.mark.parametrize("where", ["style", "source", "target", "mask"])
def test_nan_and_inf_are_refused_naming_the_pixel(where):
    style, src, tgt, mask = STYLE.copy(), SRC.copy(), TGT.copy(), np.ones((36, 44), np.float32)
    {"style": style, "source": src, "target": tgt, "mask": mask}[where][5, 7] = math.nan
    e = error_of(style, [(src, tgt)], mask)
    subject = {"style": "style", "source": "guides[0][0]", "target": "guides[0][1]", "mask": "mask"}
    assert e.subject == subject[where]
    assert "non-finite value (NaN or Inf) at pixel (7, 5)" in e.message
    src[1, 2] = math.inf
    assert "non-finite" in error_of(STYLE, [(src, TGT)]).message


@pytest.mark.parametrize("kwargs, subject", [
    ({"patch_size": 4}, "patch_size"),
    ({"patch_size": 67}, "patch_size"),
    ({"uniformity": -1.0}, "uniformity"),
    ({"uniformity": math.inf}, "uniformity"),
    ({"pyramid_levels": 0}, "pyramid_levels"),
    ({"search_vote_iters": 1001}, "search_vote_iters"),
    ({"patch_match_iters": -1}, "patch_match_iters"),
    ({"style_weight": -0.5}, "style_weight"),
    ({"style_weight": math.nan}, "style_weight"),
    ({"threads": 2000}, "threads"),
    ({"seed": -1}, "seed"),
    ({"seed": 2 ** 64}, "seed"),
    ({"seed": 1.5}, "seed"),
    ({"vote": "median"}, "vote"),
    ({"dtype": np.float64}, "dtype"),
    ({"dtype": "not a dtype"}, "dtype"),
    ({"progress": 3}, "progress"),
])
def test_parameters_out_of_range_name_the_argument(kwargs, subject):
    assert error_of(STYLE, [(SRC, TGT)], **kwargs).subject == subject


def test_bad_guide_lists():
    assert error_of(STYLE, []).subject == "guides"
    assert error_of(STYLE, [(SRC,)]).subject == "guides[0]"
    assert error_of(STYLE, [(SRC, TGT), (SRC, TGT, -1.0)]).subject == "guides[1][2]"
    assert error_of(STYLE, [(SRC, TGT, "heavy")]).subject == "guides[0][2]"
    assert error_of(STYLE, [(SRC, TGT)] * 65).subject == "guides"


def test_file_errors_are_oserrors_naming_the_file(tmp_path):
    missing = tmp_path / "missing.png"
    with pytest.raises(emaki.FileError) as e:
        emaki.read_image(missing)
    assert isinstance(e.value, OSError) and e.value.filename == str(missing)
    assert e.value.subject == str(missing)
    bad = tmp_path / "bad.png"
    bad.write_bytes(b"\x89PNG\r\n\x1a\n" + b"junk" * 10)
    with pytest.raises(emaki.FileError, match="bad.png"):
        emaki.read_image(bad)
    with pytest.raises(emaki.FileError, match="no_folder"):
        emaki.write_image(tmp_path / "no_folder" / "x.png", STYLE)
