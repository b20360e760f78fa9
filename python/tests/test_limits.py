"""What a call may ask for is checked before the work and per call: the estimated peak memory
(max_memory_mb, the machine's), array sizes before any layout copy, devices given as files, and
error text that stays valid UTF-8 however an echoed value was cut."""

import resource

import numpy as np
import pytest

import emaki
from test_shot import tiny


def small(seed, shape=(24, 32, 3)):
    return np.random.default_rng(seed).random(shape, dtype=np.float32)


def test_a_value_cut_inside_a_character_is_still_an_input_error():
    # 1 + 2k bytes: the 80-byte cut falls inside a two-byte character.
    with pytest.raises(emaki.InputError) as e:
        emaki.synthesize(small(1), [(small(2), small(3))], vote="a" + "\u00e9" * 100)
    assert e.value.subject == "vote"
    assert "(201 bytes)" in str(e.value)


def test_a_zero_stride_array_is_not_copied_before_the_size_check():
    huge = np.broadcast_to(np.float32(0.5), (16384, 16384, 4))  # 4 GB as a copy, 4 bytes here
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    with pytest.raises(emaki.InputError) as e:
        emaki.synthesize(huge, [(small(2), small(3))])
    assert e.value.subject == "guides[0][0]"
    assert "is 32x24 but the style 'style' is 16384x16384" in str(e.value)
    grown_kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before
    assert grown_kb < 512 * 1024, grown_kb


def test_max_memory_mb_refuses_a_run_before_it_writes(tmp_path):
    shot = emaki.Shot.from_dict(tiny(tmp_path / "out"))
    with pytest.raises(emaki.InputError) as e:
        shot.run(max_memory_mb=1)
    assert e.value.subject == "max_memory_mb"
    assert "needs about" in str(e.value) and "the 1 MB allowed" in str(e.value)
    with pytest.raises(emaki.InputError) as e:
        shot.composite(max_memory_mb=0)
    assert e.value.subject == "max_memory_mb"
    assert not (tmp_path / "out").exists()


def test_a_shot_too_large_for_the_machine_fails_at_once(tmp_path):
    d = tiny(tmp_path / "out")
    d["source"]["size"] = [16384, 16384]  # within the pixel budget; ~100 GB at its peak
    shot = emaki.Shot.from_dict(d)
    with pytest.raises(emaki.Error) as e:
        shot.run()
    assert "16384x16384 frames needs about" in str(e.value)
    assert not (tmp_path / "out").exists()


def test_devices_are_not_regular_files(tmp_path):
    with pytest.raises(emaki.FileError) as e:
        emaki.Shot.load("/dev/zero")
    assert "is not a regular file" in str(e.value)
    d = tiny(tmp_path / "out")
    d["exemplars"]["pastel"]["painting"] = "/dev/zero"
    with pytest.raises(emaki.InputError) as e:
        emaki.Shot.from_dict(d)
    assert e.value.subject == "exemplars.pastel.painting"
    assert "'/dev/zero' is not a regular file" in str(e.value)
