"""emaki.view(): the page's server from Python, on loopback, confined to its folder."""

import json
import pathlib
import urllib.error
import urllib.request

import numpy as np
import pytest

import emaki


def get(url):
    try:
        with urllib.request.urlopen(url, timeout=30) as r:
            return r.status, r.read()
    except urllib.error.HTTPError as e:
        return e.code, b""


def test_view_serves_a_folders_frames_and_stops(tmp_path):
    out = tmp_path / "out"
    (out / "composite").mkdir(parents=True)
    emaki.write_image(out / "composite" / "frame_0003.png", np.full((6, 8, 3), 0.5, np.float32))
    (tmp_path / "secret.txt").write_text("SECRET")
    with emaki.view(out) as v:
        assert v.url == "http://127.0.0.1:%d/" % v.port
        status, body = get(v.url + "api/outputs")
        assert status == 200
        sequences = json.loads(body)["outputs"][0]["sequences"]
        assert sequences[0]["name"] == "composite" and sequences[0]["frames"] == [3]
        assert get(v.url + "files/0/composite/frame_0003.png")[0] == 200
        assert get(v.url + "files/0/%2e%2e/secret.txt")[0] == 404
    with pytest.raises(OSError):
        urllib.request.urlopen(v.url, timeout=5)


def test_view_of_a_missing_folder_is_an_error(tmp_path):
    with pytest.raises(emaki.FileError, match="not a folder"):
        emaki.view(tmp_path / "missing")
