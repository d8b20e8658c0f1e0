"""docs/python.md runs as written: every ```python block of the page, in order, in one namespace
(the ```py blocks are the ones that need a running session of yours or files of yours)."""

import os
import re

ROOT = os.environ.get("CALIPER_SOURCE_DIR",
                      os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
PAGE = os.path.join(ROOT, "docs", "python.md")


def blocks():
    text = open(PAGE).read()
    return re.findall(r"^```python\n(.*?)^```", text, flags=re.S | re.M)


def test_the_page_has_examples():
    assert len(blocks()) >= 7


def test_the_page_runs_as_written(capsys):
    namespace = {"__name__": "docs_python"}
    try:
        for i, block in enumerate(blocks()):
            exec(compile(block, f"{PAGE} block {i + 1}", "exec"), namespace)
    finally:
        if "local" in namespace:
            namespace["local"].close()
    out = capsys.readouterr().out
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
