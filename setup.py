"""Builds the extension meshmotion._core with the project's own CMake build (the target
meshmotion_python over meshmotion::compiled) for the interpreter running pip, then lets
setuptools package it with the pure-Python part (python/meshmotion/).

    /usr/bin/python3 -m pip install --no-build-isolation .

MESHMOTION_BUILD_DIR=path reuses (and updates) that CMake build tree instead of a fresh one
under build/; MESHMOTION_BUILD_JOBS sets the parallel jobs (default: the CPU count).
"""

import os
import pathlib
import re
import shutil
import subprocess
import sys
import sysconfig

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = pathlib.Path(__file__).resolve().parent


def version():
    text = (ROOT / "include" / "meshmotion" / "version.hpp").read_text()
    return re.search(r'MESHMOTION_VERSION_STRING "([^"]+)"', text).group(1)


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        given = os.environ.get("MESHMOTION_BUILD_DIR")
        build_dir = pathlib.Path(given or ROOT / "build" / "pip").resolve()
        jobs = os.environ.get("MESHMOTION_BUILD_JOBS", str(os.cpu_count() or 1))
        # A build tree of the user's keeps its configuration (and may be in use by its tests).
        if not (given and (build_dir / "CMakeCache.txt").exists()):
            build_dir.mkdir(parents=True, exist_ok=True)
            subprocess.run(["cmake", "-S", str(ROOT), "-B", str(build_dir), "-DCMAKE_BUILD_TYPE=Release",
                            f"-DMESHMOTION_PYTHON={sys.executable}", "-DMESHMOTION_BUILD_PYTHON=ON",
                            "-DMESHMOTION_BUILD_TESTS=OFF", "-DMESHMOTION_BUILD_EXAMPLES=OFF", "-DMESHMOTION_INSTALL=OFF"],
                           check=True)
        subprocess.run(["cmake", "--build", str(build_dir), "--target", "meshmotion_python", "-j", jobs], check=True)
        built = build_dir / "python" / "meshmotion" / ("_core" + sysconfig.get_config_var("EXT_SUFFIX"))
        if not built.exists():
            sys.exit(f"setup.py: the CMake build in {build_dir} made no {built.name} (was pybind11 found for {sys.executable}?)")
        target = pathlib.Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(built, target)


# setuptools' own build folders go under build/setuptools, beside the CMake trees.
setup(version=version(), ext_modules=[Extension("meshmotion._core", sources=[])], cmdclass={"build_ext": CMakeBuild},
      options={"build": {"build_base": str(ROOT / "build" / "setuptools")}})
