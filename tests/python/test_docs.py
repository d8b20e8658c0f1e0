"""docs/python.md runs as written and prints what its comments promise: every ```python block of
the page, in order, in one namespace, as tests/docs/run_doc_blocks.py extracts them (its markers
honoured: `skip` blocks are left out, `fails` blocks must raise, `expect` must match). The ```py
blocks are the ones that need a running session of yours or files of yours. The runner itself
runs the whole page, sh blocks too, in a fresh HOME (ctest docs_python)."""

import importlib.util
import os
import re

import pytest

ROOT = os.environ.get("CALIPER_SOURCE_DIR",
                      os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
PAGE = os.path.join(ROOT, "docs", "python.md")


def load_runner():
    spec = importlib.util.spec_from_file_location(
        "run_doc_blocks", os.path.join(ROOT, "tests", "docs", "run_doc_blocks.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def blocks():
    return [b for b in load_runner().extract(PAGE, "docs/python.md") if b.language == "python"]


def test_the_page_has_examples():
    assert len(blocks()) >= 7


def test_the_page_runs_as_written(capsys):
    namespace = {"__name__": "docs_python"}
    out = []
    try:
        for block in blocks():
            if "skip" in block.options:
                continue
            code = compile("\n" * block.line + block.code, PAGE, "exec")  # the page's line numbers
            if "fails" in block.options:
                with pytest.raises(Exception):
                    exec(code, namespace)
            else:
                exec(code, namespace)
            printed = capsys.readouterr()
            out.append(printed.out)
            if "expect" in block.options:
                assert re.search(block.options["expect"], printed.out + printed.err,
                                 re.M), block.where
    finally:
        if "local" in namespace:
            namespace["local"].close()
    out = "".join(out) + capsys.readouterr().out
    # what the page's comments promise
    assert "['model0@" in out and "STOPPED 0.001" in out
    assert "<caliper.Data 100 samples of 2 channels" in out
    assert "elbow_flexer - no actuator 'elbow_flexer'" in out
    assert "value must be finite; element 0 is NaN" in out
    assert "(250, 3)" in out
    assert "undo set the mass of forearm to 1.5 kg" in out
    assert "[Event(step=100, kind='command', target='elbow_flexor'" in out
    assert "[0.  0.1 0.2]" in out  # the keyframes' times [s] from the reset
    finals = [float(v) for v in re.findall(r"'ecce_arm.forearm.mass': \[[0-9.]+\]\} (\S+)", out)]
    assert len(finals) == 3 and finals[0] > finals[1] > finals[2]  # heavier hangs lower
