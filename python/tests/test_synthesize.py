"""emaki.synthesize against `emaki synth` on the same data, bit for bit, and its options."""

import sys

import numpy as np
import pytest

import emaki
from conftest import GUIDES, cli_guide_args, guides_of, run_cli


def test_bit_identical_to_emaki_synth_on_stylit(stylit_small, tmp_path):
    files = stylit_small["files"]
    run_cli("synth", "-style", files["style"], *cli_guide_args(files), "-output",
            tmp_path / "out.png", "--nnf-out", tmp_path / "nnf.exr", "--error-out",
            tmp_path / "err.exr", "--quiet")
    run_cli("synth", "-style", files["style"], *cli_guide_args(files), "-output",
            tmp_path / "out.exr", "--output-depth", "float", "--quiet")
    a = stylit_small["arrays"]
    image, nnf, error = emaki.synthesize(a["style"], guides_of(stylit_small, "arrays"),
                                         nnf=True, error=True)
    assert image.dtype == np.uint8 and image.shape == (228, 300, 3)
    assert np.array_equal(image, emaki.read_image(tmp_path / "out.png"))
    assert np.array_equal(nnf.astype(np.float32), emaki.read_image(tmp_path / "nnf.exr"))
    assert np.array_equal(error, emaki.read_image(tmp_path / "err.exr"))
    as_float = emaki.synthesize(a["style"], guides_of(stylit_small, "arrays"), dtype=np.float32)
    assert as_float.dtype == np.float32
    assert np.array_equal(as_float, emaki.read_image(tmp_path / "out.exr"))


def test_gray_style_and_mask_match_emaki_synth(stylit_small, tmp_path):
    """An RGB style whose channels are equal counts as one channel and comes back as RGB;
    the mask adds alpha. Options are passed through as the CLI passes them."""
    a = stylit_small["arrays"]
    gray = np.repeat(a["style"][:, :, 1:2], 3, axis=2)
    yy, xx = np.mgrid[0:228, 0:300]
    mask = (((xx - 150) ** 2 + (yy - 114) ** 2) < 90 ** 2).astype(np.uint8) * 255
    emaki.write_image(tmp_path / "gray.png", gray)
    emaki.write_image(tmp_path / "mask.png", mask)
    files = stylit_small["files"]
    run_cli("synth", "-style", tmp_path / "gray.png", "-weight", "2", *cli_guide_args(files, 0.25),
            "--mask", tmp_path / "mask.png", "-uniformity", "2000", "-patchsize", "7",
            "--seed", "9", "--vote", "plain", "-output", tmp_path / "out.png", "--quiet")
    out = emaki.synthesize(gray, guides_of(stylit_small, "arrays", 0.25), mask, style_weight=2,
                           uniformity=2000, patch_size=7, seed=9, vote="plain")
    assert out.shape == (228, 300, 4)
    assert np.array_equal(out, emaki.read_image(tmp_path / "out.png"))


def test_results_do_not_depend_on_threads(stylit_small):
    a = stylit_small["arrays"]
    runs = [emaki.synthesize(a["style"], guides_of(stylit_small, "arrays"), threads=t,
                             dtype="float32") for t in (1, 2, 0)]
    assert np.array_equal(runs[0], runs[1]) and np.array_equal(runs[0], runs[2])


def noise(shape, seed, dtype=np.float32):
    return np.random.default_rng(seed).random(shape, dtype=np.float32).astype(dtype)


def test_hxw_style_gives_hxw_result():
    style = noise((40, 48), 1)
    out = emaki.synthesize(style, [(noise((40, 48, 2), 2), noise((36, 44, 2), 3))])
    assert out.shape == (36, 44) and out.dtype == np.float32
    with_mask = emaki.synthesize(style, [(noise((40, 48, 2), 2), noise((36, 44, 2), 3))],
                                 np.ones((36, 44), np.uint8))
    assert with_mask.shape == (36, 44, 2)


def test_integer_results_are_rounded_as_png_files_are():
    style, src, tgt = noise((40, 48, 3), 1), noise((40, 48, 3), 2), noise((36, 44, 3), 3)
    f = emaki.synthesize(style, [(src, tgt)])
    u8 = emaki.synthesize(style, [(src, tgt)], dtype="uint8")
    u16 = emaki.synthesize(style, [(src, tgt)], dtype=np.uint16)
    assert np.array_equal(u8, (np.clip(f, 0, 1) * np.float32(255) + np.float32(0.5)).astype(np.uint8))
    assert np.array_equal(u16, (np.clip(f, 0, 1) * np.float32(65535) + np.float32(0.5)).astype(np.uint16))


def test_seed_and_schedule_options_change_the_result():
    style, src, tgt = noise((40, 48, 3), 1), noise((40, 48, 3), 2), noise((36, 44, 3), 3)
    base = emaki.synthesize(style, [(src, tgt)])
    assert not np.array_equal(base, emaki.synthesize(style, [(src, tgt)], seed=2))
    assert not np.array_equal(base, emaki.synthesize(style, [(src, tgt)], search_vote_iters=1,
                                                     patch_match_iters=1))
    assert np.array_equal(base, emaki.synthesize(style, [(src, tgt)], seed=1))


def test_progress_is_called_per_level_and_its_exception_propagates():
    style, src, tgt = noise((64, 64, 3), 1), noise((64, 64, 3), 2), noise((64, 64, 3), 3)
    calls = []
    emaki.synthesize(style, [(src, tgt)], progress=lambda p: calls.append((p["level"], p["levels"])))
    assert calls and calls[0][0] == 0 and all(n == calls[0][1] for _, n in calls)
    assert [l for l, _ in calls] == list(range(calls[0][1]))
    returned = object()
    count = sys.getrefcount(returned)
    emaki.synthesize(style, [(src, tgt)], progress=lambda p: returned)
    assert sys.getrefcount(returned) == count  # what progress returns is not kept

    class Stop(Exception):
        pass

    def stop(p):
        if p["level"] == 1:
            raise Stop("from progress")

    with pytest.raises(Stop):
        emaki.synthesize(style, [(src, tgt)], progress=stop)


def test_numpy_scalars_are_accepted_as_numbers():
    style, src, tgt = noise((40, 48, 3), 1), noise((40, 48, 3), 2), noise((36, 44, 3), 3)
    plain = emaki.synthesize(style, [(src, tgt, 0.5)], seed=3, patch_size=5)
    same = emaki.synthesize(style, [(src, tgt, np.float32(0.5))], seed=np.uint64(3),
                            patch_size=np.int64(5))
    assert np.array_equal(plain, same)
