"""`cmake --install` puts the package where Debian's python3 finds it: under a prefix,
PREFIX/lib/python3.X/dist-packages/caliper (for /usr/local that is on python3's own path), and
it imports and works from there."""

import os
import subprocess
import sys

BUILD = os.path.dirname(os.path.abspath(os.environ.get("CALIPER_BIN_DIR", "build/bin")))


def test_the_installed_package_imports_from_its_site_directory(tmp_path):
    prefix = tmp_path / "prefix"
    subprocess.run(["cmake", "--install", BUILD, "--component", "python", "--prefix", str(prefix)],
                   check=True, capture_output=True)
    version = f"python{sys.version_info.major}.{sys.version_info.minor}"
    site = prefix / "lib" / version / "dist-packages"
    installed = sorted(p.name for p in (site / "caliper").iterdir())
    assert "__init__.py" in installed and "_caliper.pyi" in installed and "py.typed" in installed
    assert any(n.startswith("_caliper.") and n.endswith(".so") for n in installed), installed
    # Debian's python3 reads /usr/local/lib/python3.X/dist-packages: the same layout
    assert f"/usr/local/lib/{version}/dist-packages" in sys.path
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["PYTHONPATH"] = str(site)
    out = subprocess.run([sys.executable, "-c",
                          "import caliper; print(caliper.__file__); "
                          "print(caliper.Box(0, 1, (2,)).shape)"],
                         env=env, check=True, capture_output=True, text=True, cwd=tmp_path).stdout
    assert out.splitlines()[0].startswith(str(site)), out
    assert out.splitlines()[1] == "(2,)"
