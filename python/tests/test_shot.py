"""emaki.Shot: the shot API from Python, against `emaki run` on the same shot."""

import hashlib
import pathlib
import threading

import pytest

import emaki
from conftest import ROOT, run_cli

DATA = ROOT / "tests" / "data"


def tiny(folder):
    """A 64x36, 3-frame shot of the Fox: a temporal base layer and a chunkable outline."""
    return {
        "source": {"scene": str(DATA / "scenes" / "Fox.glb"), "clip": "Walk", "frames": [0, 2],
                   "size": [64, 36], "aa": 1, "camera": {"azimuth": 35, "elevation": 14}},
        "exemplars": {"pastel": {"painting": str(DATA / "stylit" / "source_style.png")}},
        "layers": {
            "base": {"kind": "base", "exemplar": "pastel", "guides": {"normal": 1.0, "diffuse": 1.5}},
            "ink": {"kind": "outline", "exemplar": "pastel", "temporal": False},
        },
        "outputs": {"folder": str(folder), "mp4": False},
    }


def toml_text(d, prefix=""):
    """The same shot written as a file by hand (tests that from_dict means the same)."""
    lines = []
    for k, v in d.items():
        if isinstance(v, dict):
            continue
        lines.append(f"{k} = {value(v)}")
    out = ([f"[{prefix}]"] if prefix and lines else []) + lines
    for k, v in d.items():
        if isinstance(v, dict) and not (prefix.endswith("guides") or k == "guides"):
            out += toml_text(v, f"{prefix}.{k}" if prefix else k)
        elif isinstance(v, dict):
            out.append(f"{k} = {{ " + ", ".join(f"{a} = {value(b)}" for a, b in v.items()) + " }")
    return out


def value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return '"' + v + '"'
    if isinstance(v, list):
        return "[" + ", ".join(value(x) for x in v) + "]"
    return repr(v)


def digests(folder):
    """The outputs in `folder`: not emaki's hidden files or its exemplars' reference passes."""
    folder = pathlib.Path(folder)
    return {str(p.relative_to(folder)): hashlib.md5(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file() and not p.name.startswith(".")
            and p.relative_to(folder).parts[0] != "references"}


def test_a_shot_run_from_python_equals_emaki_run(tmp_path):
    shot = emaki.Shot.from_dict(tiny(tmp_path / "py"))
    assert shot.frames == (0, 2) and shot.size == (64, 36) and shot.layers == ["base", "ink"]
    seen = []
    report = shot.run(progress=seen.append)
    assert report["synthesized"] == 6 and report["composited"] == 3
    assert [s["layer"] for s in seen if s["layer"]] == ["base", "ink"] * 3
    shot_file = tmp_path / "cli.toml"
    shot_file.write_text("\n".join(toml_text(tiny(tmp_path / "cli"))) + "\n")
    run_cli("run", shot_file)
    py, cli = digests(tmp_path / "py"), digests(tmp_path / "cli")
    assert len(py) == 19 and py == cli  # 3 x (composite, layered, 2 layers x (exr, png)) + sheet
    # Resuming: nothing left to do.
    assert shot.run()["synthesized"] == 0
    assert emaki.Shot.load(str(shot_file)).run(threads=1)["reused"] == 6
    # A frame's layers one after another: the same files.
    apart = emaki.Shot.from_dict(tiny(tmp_path / "apart"))
    assert apart.run(one_layer_at_a_time=True)["synthesized"] == 6
    assert digests(tmp_path / "apart") == py


def test_composite_flicker_and_plan(tmp_path):
    shot = emaki.Shot.from_dict(tiny(tmp_path / "out"))
    shot.run(previews=False)
    assert shot.composite(frames=(1, 2), previews=False) == 2
    f = shot.flicker("base", maps=True)
    assert f["frames"] == (0, 2) and len(f["per_frame"]) == 2 and f["mean"] > 0
    maps = sorted(p.name for p in (shot.output_folder / "qa" / "flicker" / "base").iterdir())
    assert maps == ["frame_0001.png", "frame_0002.png"]
    plan = shot.plan(chunk=2)
    assert plan["format"] == "emaki-plan-1"
    kinds = [t["kind"] for t in plan["tasks"]]
    assert kinds.count("layer") == 3  # base whole, ink in two chunks
    assert all(t["done"] for t in plan["tasks"] if t["kind"] != "previews")


def test_errors_name_the_key_or_the_argument(tmp_path):
    bad = tiny(tmp_path / "out")
    bad["layers"]["base"]["opacty"] = 0.5
    with pytest.raises(emaki.InputError) as e:
        emaki.Shot.from_dict(bad)
    assert e.value.subject == "layers.base.opacty" and "did you mean 'opacity'" in str(e.value)
    shot = emaki.Shot.from_dict(tiny(tmp_path / "out"))
    with pytest.raises(emaki.InputError) as e:
        shot.run(layers=["nope"])
    assert e.value.subject == "layers"
    with pytest.raises(emaki.InputError) as e:
        shot.run(frames=(0, 9))
    assert e.value.subject == "frames"
    with pytest.raises(emaki.InputError) as e:
        shot.flicker("nope")
    assert e.value.subject == "layer"
    with pytest.raises(emaki.InputError) as e:
        shot.plan(chunk=0)
    assert e.value.subject == "chunk"
    with pytest.raises(emaki.Error) as e:
        emaki.Shot.load(str(tmp_path / "missing.toml"))
    assert e.value.subject.endswith("missing.toml")
    assert not (tmp_path / "out").exists()  # refused before anything was written


@pytest.mark.parametrize("kwargs, subject", [
    (dict(layers="base"), "layers"), (dict(layers=[1]), "layers"), (dict(frames="0-3"), "frames"),
    (dict(frames=True), "frames"), (dict(threads="2"), "threads"),
    (dict(max_memory_mb="8G"), "max_memory_mb")])
def test_wrong_argument_types_are_input_errors_naming_the_argument(tmp_path, kwargs, subject):
    shot = emaki.Shot.from_dict(tiny(tmp_path / "out"))
    with pytest.raises(emaki.InputError) as e:
        shot.run(**kwargs)
    assert e.value.subject == subject and "expected" in str(e.value)
    assert not (tmp_path / "out").exists()


def test_paths_are_pathlib_both_ways(tmp_path):
    shot_file = tmp_path / "tiny.toml"
    shot_file.write_text("\n".join(toml_text(tiny(tmp_path / "out"))) + "\n")
    for shot in (emaki.Shot.load(shot_file), emaki.Shot(shot_file),
                 emaki.Shot.from_dict(tiny(tmp_path / "out"), tmp_path / "d.toml")):
        assert isinstance(shot.path, pathlib.Path) and shot.output_folder == tmp_path / "out"
        assert repr(shot).startswith("<emaki.Shot '") and "layers [base, ink]" in repr(shot)
    assert emaki.Shot(shot_file).path == shot_file
    report = emaki.Shot(shot_file).run(threads=1)
    assert report["previews"] and all(isinstance(p, pathlib.Path) for p in report["previews"])


def test_a_raising_progress_callback_stops_the_run(tmp_path):
    shot = emaki.Shot.from_dict(tiny(tmp_path / "out"))

    def stop(p):
        if p["done"] >= 2:
            raise RuntimeError("enough")

    with pytest.raises(RuntimeError, match="enough"):
        shot.run(progress=stop)
    # What finished stays finished; the rest is done on the next run.
    assert shot.run()["reused"] == 2


def test_the_gil_is_released_while_a_shot_runs(tmp_path):
    shot = emaki.Shot.from_dict(tiny(tmp_path / "out"))
    ticks = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(1)
            stop.wait(0.001)

    t = threading.Thread(target=count)
    t.start()
    try:
        shot.run(previews=False)
    finally:
        stop.set()
        t.join()
    assert len(ticks) > 20


def test_shot_without_a_path_is_a_type_error_naming_it():
    with pytest.raises(TypeError, match="path"):
        emaki.Shot()
