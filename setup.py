"""The scoleid Python package, built by CMake (pyproject.toml says how to install it).

The extension scoleid._core is the library's CMake target scoleid_python. It is built in
SCOLEID_BUILD_DIR when that is set (an existing build directory is reused as it is), else in
build/ (the Makefile's build directory: configured here, Release, when it has not been), for the
interpreter running this build. With SCOLEID_NO_BUILD=1 the extension already built there is
taken as it is (CMake is not run: a test of the packaging beside a build in use). Its file is then
placed beside scoleid/__init__.py, its stub and py.typed, and setuptools makes the wheel. The
version is CMakeLists.txt's project version.
"""
import glob
import os
import re
import shutil
import subprocess
import sys
import sysconfig

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = os.path.dirname(os.path.abspath(__file__))


def version():
    with open(os.path.join(ROOT, "CMakeLists.txt"), encoding="utf-8") as f:
        m = re.search(r"project\(\s*scoleid\s+VERSION\s+([0-9][0-9.]*)", f.read())
    if not m:
        raise RuntimeError("CMakeLists.txt: no 'project(scoleid VERSION x.y.z)'")
    return m.group(1)


class CMakeBuild(build_ext):
    """Builds scoleid._core with CMake and copies it where setuptools packs it."""

    def build_extension(self, ext):
        build_dir = os.path.abspath(os.environ.get("SCOLEID_BUILD_DIR") or os.path.join(ROOT, "build"))
        if os.environ.get("SCOLEID_NO_BUILD") != "1":
            if not os.path.exists(os.path.join(build_dir, "CMakeCache.txt")):
                subprocess.check_call(["cmake", "-S", ROOT, "-B", build_dir, "-DCMAKE_BUILD_TYPE=Release",
                                       "-DPYTHON_EXECUTABLE=" + sys.executable])
            jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL") or str(os.cpu_count() or 1)
            subprocess.check_call(["cmake", "--build", build_dir, "--target", "scoleid_python", "-j", jobs])
        suffix = sysconfig.get_config_var("EXT_SUFFIX")
        built = os.path.join(build_dir, "python", "scoleid", "_core" + suffix)
        if not os.path.exists(built):
            found = glob.glob(os.path.join(build_dir, "python", "scoleid", "_core*"))
            raise RuntimeError("%s: no _core%s for this interpreter (%s); the build directory was configured for "
                               "another Python (found %s): set SCOLEID_BUILD_DIR to a fresh directory"
                               % (build_dir, suffix, sys.executable, ", ".join(found) or "nothing"))
        target = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copyfile(built, target)


# setuptools' own files (the wheel's staging, egg-info) stay in the build tree, not among the sources.
SETUPTOOLS_DIR = os.path.join("build", "setuptools")
os.makedirs(os.path.join(ROOT, SETUPTOOLS_DIR), exist_ok=True)

setup(
    version=version(),
    package_dir={"": "crosscheck/python"},
    packages=["scoleid"],
    package_data={"scoleid": ["__init__.pyi", "py.typed"]},
    ext_modules=[Extension("scoleid._core", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    options={"build": {"build_base": SETUPTOOLS_DIR}, "egg_info": {"egg_base": SETUPTOOLS_DIR}},
    zip_safe=False,
)
