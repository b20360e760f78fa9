"""emaki.__version__ is the command line's version: one string from one build."""

import subprocess

import emaki
from conftest import emaki_binary


def test_version_matches_the_command_line():
    out = subprocess.run([emaki_binary(), "--version"], capture_output=True, text=True,
                         check=True).stdout
    assert out == "emaki %s\n" % emaki.__version__
    release = emaki.__version__.split("+")[0]
    assert all(part.isdigit() for part in release.split(".")), emaki.__version__
