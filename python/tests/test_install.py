"""`cmake --install` puts a package the interpreter imports with nothing of the build tree."""

import os
import pathlib
import subprocess
import sys

import pytest


def test_the_installed_package_imports_and_loads_a_model(checkpoint, tmp_path):
    build = os.environ.get("NEUFLOW_BUILD_DIR")
    if not build:
        pytest.skip("NEUFLOW_BUILD_DIR names the build (ctest sets it)")
    # Under any prefix but /usr, the interpreter's versioned folder (Debian's rule for /usr/local).
    where = f"lib/python{sys.version_info.major}.{sys.version_info.minor}/dist-packages"
    subprocess.run(["cmake", "--install", build, "--component", "python", "--prefix", str(tmp_path)], check=True,
                   capture_output=True)
    installed = tmp_path / where / "neuflow"
    assert sorted(p.name for p in installed.iterdir() if not p.name.startswith("_neuflow")) == [
        "__init__.py", "__init__.pyi", "py.typed"]
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["PYTHONPATH"] = str(tmp_path / where)
    script = ("import neuflow, sys; print(neuflow.__file__); "
              f"print(neuflow.Model({str(checkpoint)!r}, backend='cpu').info['parameters'])")
    out = subprocess.run([sys.executable, "-c", script], cwd="/", env=env, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    path, parameters = out.stdout.split()
    assert pathlib.Path(path).is_relative_to(tmp_path)
    assert parameters == "9029536"
