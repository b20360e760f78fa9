"""help() and inspect.signature() are complete: every public function, class and method has a
signature (CPython's __text_signature__, from the docstring's first line) that agrees with the
stub (emaki.pyi), and each function documents every argument in its Args section."""

import ast
import inspect
import pathlib
import pydoc
import types

import pytest

import emaki

STUB = pathlib.Path(__file__).resolve().parents[1] / "emaki.pyi"
FUNCTIONS = ["synthesize", "read_image", "write_image", "image_channels", "render", "template",
             "convert_colorspace", "view"]
REQUIRED = "<required>"


def signature(fn_def):
    """[(name, default or REQUIRED, kind)] of a stub's def."""
    a = fn_def.args
    positional = a.posonlyargs + a.args
    defaults = [REQUIRED] * (len(positional) - len(a.defaults)) + list(a.defaults)
    out = [(p.arg, d, "positional") for p, d in zip(positional, defaults)]
    if a.vararg:
        out.append((a.vararg.arg, REQUIRED, "*"))
    out += [(p.arg, REQUIRED if d is None else d, "keyword") for p, d in zip(a.kwonlyargs, a.kw_defaults)]
    return [(name, d if d is REQUIRED else ast.literal_eval(d), kind) for name, d, kind in out]


def runtime_signature(obj):
    """The same list from inspect.signature(obj)."""
    kinds = {inspect.Parameter.POSITIONAL_ONLY: "positional",
             inspect.Parameter.POSITIONAL_OR_KEYWORD: "positional",
             inspect.Parameter.VAR_POSITIONAL: "*", inspect.Parameter.KEYWORD_ONLY: "keyword"}
    return [(p.name, REQUIRED if p.default is inspect.Parameter.empty else p.default, kinds[p.kind])
            for p in inspect.signature(obj).parameters.values()]


def stub_functions(body=None):
    if body is None:
        body = ast.parse(STUB.read_text()).body
    found = {}
    for node in body:
        if isinstance(node, ast.FunctionDef) and node.name not in found:
            if not any(isinstance(d, ast.Name) and d.id == "property" for d in node.decorator_list):
                found[node.name] = signature(node)
    return found


def stub_classes():
    return {node.name: stub_functions(node.body) for node in ast.parse(STUB.read_text()).body
            if isinstance(node, ast.ClassDef) and not issubclass(getattr(emaki, node.name), BaseException)}


def test_every_public_function_is_in_the_stub():
    public = [n for n in dir(emaki) if not n.startswith("_") and isinstance(getattr(emaki, n), types.BuiltinFunctionType)]
    assert sorted(public) == sorted(FUNCTIONS)
    assert set(FUNCTIONS) <= set(stub_functions())


@pytest.mark.parametrize("name", FUNCTIONS)
def test_function_signature_agrees_with_the_stub(name):
    assert runtime_signature(getattr(emaki, name)) == stub_functions()[name]
    assert str(inspect.signature(getattr(emaki, name))) in pydoc.render_doc(getattr(emaki, name))


def test_class_and_method_signatures_agree_with_the_stub():
    classes = stub_classes()
    assert sorted(classes) == ["Shot", "Viewer"]
    for cls, methods in classes.items():
        public = {n for n, v in vars(getattr(emaki, cls)).items()
                  if not n.startswith("_") and not isinstance(v, property)}
        assert public <= set(methods), (cls, public - set(methods))
        for name, want in methods.items():
            assert runtime_signature(getattr(getattr(emaki, cls), name)) == want, (cls, name)
    # The class itself takes __init__'s arguments; a bound method drops self.
    assert runtime_signature(emaki.Shot) == classes["Shot"]["__init__"][1:]
    bound = types.MethodType(emaki.Shot.run, object())
    assert runtime_signature(bound) == classes["Shot"]["run"][1:]
    assert str(inspect.signature(emaki.Shot.plan)) == "(self, *, chunk=8, threads=1, emaki='emaki')"


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


def test_the_readme_python_section_introduces_the_shot_api():
    readme = (STUB.parents[1] / "README.md").read_text()
    section = readme.split("\n## Python\n")[1].split("\n## ")[0]
    assert "emaki.Shot" in section
