"""Inputs are read in place: the engine sees the arrays' own memory, with no copy.

Seen from outside: `progress` runs as each pyramid level starts. The finest level votes from
the style array itself and the result's alpha is read from the mask array at the end, so
what a `progress` callback writes into those arrays before the finest level shows in the
result exactly when the engine reads them in place, and not when it reads a copy. (Where the
binding reads which array, and which layouts it copies, is checked on the C++ side too:
python/arrays_test.cpp.)"""

import numpy as np

import emaki


def noise(shape, seed):
    return np.random.default_rng(seed).random(shape, dtype=np.float32)


def scribble_before_the_finest_level(*arrays):
    """A progress callback that sets every array to 0.25 as the finest level starts."""
    def progress(p):
        if p["level"] == p["levels"] - 1:
            for a in arrays:
                a[...] = 0.25
    return progress


def test_c_contiguous_float32_style_and_mask_are_read_in_place():
    style, src, tgt = noise((48, 64, 3), 1), noise((48, 64, 3), 2), noise((40, 56, 3), 3)
    src2, tgt2 = noise((48, 64), 4), noise((40, 56), 5)
    mask = np.ones((40, 56), np.float32)
    out = emaki.synthesize(style, [(src, tgt), (src2, tgt2, 0.3)], mask,
                           progress=scribble_before_the_finest_level(style, mask))
    assert out.shape == (40, 56, 4)
    assert np.all(out[..., :3] == 0.25)  # every voted pixel came from the scribbled style
    assert np.all(out[..., 3] == 0.25)  # alpha from the scribbled mask


def test_rows_at_any_stride_are_read_in_place():
    wide = noise((48, 100, 3), 1)
    style = wide[:, 10:74]  # a crop: rows 100 pixels apart
    assert not style.flags.c_contiguous
    src, tgt = noise((48, 64, 3), 2), noise((40, 56, 3), 3)
    untouched = emaki.synthesize(np.ascontiguousarray(style), [(src, tgt)])
    assert not np.all(untouched == 0.25)
    out = emaki.synthesize(style, [(src, tgt)], progress=scribble_before_the_finest_level(style))
    assert np.all(out == 0.25)
    assert np.all(wide[:, :10] != 0.25)  # the crop, not its neighbours


def test_other_layouts_are_copied_once_and_give_the_same_result():
    rgba = noise((48, 64, 4), 1)
    style = rgba[:, :, :3]  # channels not packed
    flipped = noise((48, 64, 3), 2)[::-1]  # negative row stride
    tgt = np.asfortranarray(noise((40, 56, 3), 3))
    same = emaki.synthesize(np.ascontiguousarray(style),
                            [(np.ascontiguousarray(flipped), np.ascontiguousarray(tgt))])
    # The engine reads a copy: scribbling on the array during the run changes nothing.
    out = emaki.synthesize(style, [(flipped, tgt)],
                           progress=scribble_before_the_finest_level(style))
    assert np.all(style == 0.25)
    assert np.array_equal(out, same)
