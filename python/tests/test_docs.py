"""help() is complete: each function's docstring starts with its signature, which agrees with
the stub (emaki.pyi), and documents every argument in its Args section."""

import ast
import pathlib
import pydoc

import pytest

import emaki

STUB = pathlib.Path(__file__).resolve().parents[1] / "emaki.pyi"
FUNCTIONS = ["synthesize", "read_image", "write_image", "image_channels", "render", "template",
             "convert_colorspace", "view"]


def signature(fn_def):
    a = fn_def.args
    positional = a.posonlyargs + a.args
    defaults = [None] * (len(positional) - len(a.defaults)) + list(a.defaults)
    out = [(p.arg, d, False) for p, d in zip(positional, defaults)]
    out += [(p.arg, d, True) for p, d in zip(a.kwonlyargs, a.kw_defaults)]
    return [(name, None if d is None else ast.literal_eval(d), kw) for name, d, kw in out]


def stub_functions():
    tree = ast.parse(STUB.read_text())
    found = {}
    for node in tree.body:
        if isinstance(node, ast.FunctionDef) and node.name not in found:
            found[node.name] = signature(node)
    return found


@pytest.mark.parametrize("name", FUNCTIONS)
def test_docstring_signature_agrees_with_the_stub(name):
    doc = getattr(emaki, name).__doc__
    first = doc.splitlines()[0]
    parsed = ast.parse("def " + first.split(" -> ")[0] + ": pass").body[0]
    assert signature(parsed) == stub_functions()[name]


@pytest.mark.parametrize("name", ["synthesize", "render", "template", "read_image", "write_image",
                                  "view"])
def test_every_argument_is_documented(name):
    text = pydoc.render_doc(getattr(emaki, name))
    args = text.split("Args:")[1].split("Returns:")[0] if "Returns:" in text else text.split("Args:")[1]
    for arg, _, _ in stub_functions()[name]:
        assert ("    %s:" % arg) in args, arg
    assert "Raises:" in text


def test_synthesize_help_gives_ranges_and_defaults():
    text = pydoc.render_doc(emaki.synthesize)
    for piece in ["[3, 65]. Default 5", "Default 3500", "[1, 32]", "[0, 1000]", "Default 1.",
                  "[0, 1024]", "'weighted' (default)", "Ctrl-C", "GIL", "bit for bit"]:
        assert piece in text, piece


def test_exceptions_are_documented_classes():
    assert issubclass(emaki.InputError, emaki.Error) and issubclass(emaki.InputError, ValueError)
    assert issubclass(emaki.FileError, emaki.Error) and issubclass(emaki.FileError, OSError)
    assert "subject" in emaki.Error.__doc__
