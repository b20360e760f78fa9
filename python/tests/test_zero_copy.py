"""Inputs are read in place: the engine sees the arrays' own memory, with no copy.

emaki._last_inputs() reports the data addresses the engine was handed by the last call on this
thread; emaki._input_copies() counts the layout copies the binding ever made."""

import numpy as np

import emaki


def noise(shape, seed):
    return np.random.default_rng(seed).random(shape, dtype=np.float32)


def address(a):
    return a.__array_interface__["data"][0]


def test_c_contiguous_float32_inputs_are_not_copied():
    style, src, tgt = noise((48, 64, 3), 1), noise((48, 64, 3), 2), noise((40, 56, 3), 3)
    src2, tgt2 = noise((48, 64), 4), noise((40, 56), 5)
    mask = np.ones((40, 56), np.float32)
    before = emaki._input_copies()
    emaki.synthesize(style, [(src, tgt), (src2, tgt2, 0.3)], mask)
    seen = emaki._last_inputs()
    assert emaki._input_copies() == before
    assert seen["layout_copies"] == 0 and seen["images_made"] == 0
    assert seen["style"] == address(style)
    assert seen["guides"] == [(address(src), address(tgt)), (address(src2), address(tgt2))]
    assert seen["mask"] == address(mask)


def test_rows_at_any_stride_are_read_in_place():
    wide = noise((48, 100, 3), 1)
    style = wide[:, 10:74]  # a crop: rows 100 pixels apart
    assert not style.flags.c_contiguous
    src, tgt = noise((48, 64, 3), 2), noise((40, 56, 3), 3)
    before = emaki._input_copies()
    out = emaki.synthesize(style, [(src, tgt)])
    assert emaki._input_copies() == before
    assert emaki._last_inputs()["style"] == address(style)
    assert np.array_equal(out, emaki.synthesize(np.ascontiguousarray(style), [(src, tgt)]))


def test_other_layouts_are_copied_once_and_give_the_same_result():
    rgba = noise((48, 64, 4), 1)
    style = rgba[:, :, :3]  # channels not packed
    flipped = noise((48, 64, 3), 2)[::-1]  # negative row stride
    tgt = np.asfortranarray(noise((40, 56, 3), 3))
    before = emaki._input_copies()
    out = emaki.synthesize(style, [(flipped, tgt)])
    assert emaki._input_copies() == before + 3
    assert emaki._last_inputs()["layout_copies"] == 3
    same = emaki.synthesize(np.ascontiguousarray(style),
                            [(np.ascontiguousarray(flipped), np.ascontiguousarray(tgt))])
    assert np.array_equal(out, same)
