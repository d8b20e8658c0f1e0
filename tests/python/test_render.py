"""TendonEnv.render(): the Scene Renderer's view as an RGB array, when one runs in the session
(caliper-renderer under X; `launch/caliper test` starts Xvfb itself). The frames are written to
$CALIPER_ARTIFACT_DIR (or the test's temporary folder) to be looked at."""

import os
import subprocess
import time

import numpy as np
import pytest

import caliper

from conftest import SCENE


def renderer_or_skip():
    if not os.environ.get("DISPLAY"):
        pytest.skip("no DISPLAY: the Scene Renderer needs X (launch/caliper test starts Xvfb)")
    try:
        return caliper.binary("caliper-renderer")
    except FileNotFoundError as e:
        pytest.skip(f"caliper-renderer is not built (CALIPER_GUI off): {e}")


def test_render_returns_the_renderers_view_as_rgb(tmp_path):
    renderer = renderer_or_skip()
    with caliper.LocalSession(models=1, scene=SCENE) as session:
        log = open(tmp_path / "renderer.out", "wb")
        p = subprocess.Popen([renderer, "--nameservice", session.address, "-o", "log.service=none",
                              "-o", f"log.spool_dir={tmp_path}/spool"], stdout=log,
                             stderr=subprocess.STDOUT)
        try:
            deadline = time.monotonic() + 30
            while not any(c.kind == "Renderer" for c in session.components()):
                assert p.poll() is None, open(tmp_path / "renderer.out").read()
                assert time.monotonic() < deadline, "the renderer did not bind"
                time.sleep(0.1)
            env = caliper.TendonEnv(session.model("model0"), session=session,
                                    actuators=["elbow_flexor", "elbow_extensor"],
                                    observations=["ecce_arm.elbow.position"],
                                    frames_per_action=50, render_mode="rgb_array",
                                    render_size=(320, 240))
            env.reset(seed=1)
            first = env.render()
            for _ in range(40):
                obs, *_ = env.step(np.array([12.0, 0.0]))  # bend the elbow hard for 2 s
            second = env.render()
            assert obs[0] > 0.5, "the elbow bent"
            for frame in (first, second):
                assert frame.shape == (240, 320, 3) and frame.dtype == np.uint8
                assert frame.std() > 5, "a picture, not a blank frame"
            changed = np.mean(np.any(first != second, axis=2))
            assert changed > 0.005, f"the view shows the arm moving ({changed:.2%} of pixels)"
            out = os.environ.get("CALIPER_ARTIFACT_DIR", str(tmp_path))
            os.makedirs(out, exist_ok=True)
            from PIL import Image
            for name, frame in (("python_render_reset.png", first), ("python_render_bent.png",
                                                                      second)):
                Image.fromarray(frame).save(os.path.join(out, name))
            assert caliper.TendonEnv(session.model("model0"), session=session,
                                     actuators=["elbow_flexor"],
                                     observations=["ecce_arm.elbow.position"]).render() is None
        finally:
            p.terminate()
            p.wait(timeout=20)
