"""The package's typing: the stubs of the extension (caliper/_caliper.pyi) name exactly what the
module has, every public name has a docstring, and help() on the main classes reads."""

import ast
import inspect
import os
import pydoc

import caliper
from caliper import _caliper

STUB = os.path.join(os.path.dirname(caliper.__file__), "_caliper.pyi")


def stub_names():
    tree = ast.parse(open(STUB).read())
    out = {}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            members = set()
            for item in node.body:
                if isinstance(item, (ast.FunctionDef, ast.AsyncFunctionDef)):
                    members.add(item.name)
                elif isinstance(item, ast.AnnAssign) and isinstance(item.target, ast.Name):
                    members.add(item.target.id)
            out[node.name] = members
        elif isinstance(node, ast.FunctionDef):
            out[node.name] = None
    return out


def runtime_members(cls):
    return {n for n in dir(cls) if not n.startswith("__") and not n.startswith("_pybind11")}


def test_stubs_name_exactly_the_module():
    stubs = stub_names()
    module = {n for n in dir(_caliper) if not n.startswith("__")}
    assert set(stubs) == module, (set(stubs) ^ module)
    for name, members in stubs.items():
        if members is None:
            continue
        declared = {m for m in members if m != "__init__"}
        assert declared == runtime_members(getattr(_caliper, name)), \
            (name, declared ^ runtime_members(getattr(_caliper, name)))


def test_every_public_name_is_documented():
    undocumented = []
    for name in caliper.__all__:
        obj = getattr(caliper, name)
        if inspect.ismodule(obj):
            continue
        if not (obj.__doc__ or "").strip():
            undocumented.append(name)
        if inspect.isclass(obj):
            for member, value in vars(obj).items():
                if member.startswith("_") or not callable(value):
                    continue
                if not (getattr(value, "__doc__", "") or "").strip():
                    undocumented.append(f"{name}.{member}")
    assert undocumented == []


def test_help_reads():
    text = pydoc.render_doc(caliper.Model, renderer=pydoc.plaintext)
    assert "step(self: caliper._caliper.Model, n: int = 1) -> int" in text
    assert "Runs `n` steps now" in text
    assert "record(" in text and "losslessly" in text
