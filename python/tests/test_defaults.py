"""One default for the reference camera's elevation (exemplar::kDefaultReferenceElevationDeg):
the shot file's exemplars.NAME.elevation (its docs table is made from the schema), `emaki
template --elevation`, emaki.template(elevation=) and the Blender exporter's --elevation all
show and use the same value. A painting made over a default template then matches a shot's
default guides."""

import inspect
import re
import subprocess

import numpy as np

import emaki
from conftest import ROOT, emaki_binary


def shot_file_default():
    table = (ROOT / "docs" / "shot_file.md").read_text()
    m = re.search(r"^\| `exemplars\.NAME\.elevation` \| number \| `([-\d.]+)` \|", table, re.M)
    assert m, "no exemplars.NAME.elevation row in docs/shot_file.md"
    return float(m.group(1))


def cli_default():
    out = subprocess.run([emaki_binary(), "template", "--help"], capture_output=True, text=True,
                         check=True).stdout
    m = re.search(r"--elevation [^\n]*=([-\d.]+)\n", out)  # "--elevation FLOAT:... =10"
    assert m, out
    return float(m.group(1))


def exporter_default():
    text = (ROOT / "tools" / "blender" / "emaki_passes.py").read_text()
    m = re.search(r'"--elevation", type=float, default=([-\d.]+)', text)
    assert m, "no --elevation option in emaki_passes.py"
    return float(m.group(1))


def python_documented_default():
    return inspect.signature(emaki.template).parameters["elevation"].default


def test_every_front_end_has_one_reference_elevation():
    want = shot_file_default()
    assert cli_default() == want
    assert exporter_default() == want
    assert python_documented_default() == want


def test_python_template_uses_the_documented_default():
    want = shot_file_default()
    small = dict(size=(40, 30), aa=1, threads=1)
    default = emaki.template(**small)["template"]
    assert np.array_equal(default, emaki.template(elevation=want, **small)["template"])
    assert not np.array_equal(default, emaki.template(elevation=want + 20, **small)["template"])
