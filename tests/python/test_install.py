"""`cmake --install` puts a working package into a prefix (Debian's dist-packages layout)."""
import os
import pathlib
import subprocess
import sys

import pytest

import strata


def test_the_installed_package_imports_from_its_prefix(tmp_path):
    build = pathlib.Path(strata.__file__).resolve().parents[2]
    if not (build / "cmake_install.cmake").is_file():
        pytest.skip(f"{build} is not a build directory (the module is imported from elsewhere)")
    subprocess.run(["cmake", "--install", str(build), "--prefix", str(tmp_path)], check=True,
                   capture_output=True)
    site = tmp_path / "lib" / f"python{sys.version_info.major}.{sys.version_info.minor}" / \
        "dist-packages"
    assert (site / "strata" / "__init__.py").is_file()
    env = dict(os.environ, PYTHONPATH=str(site))
    code = "import strata; print(strata.__file__); print(len(strata.VoxelMap(0.5).voxels(" \
           "[0, 0, 0], [1, 1, 1])['hits']))"
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                          cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == [str(site / "strata" / "__init__.py"), "0"]
