"""scoleid installs as a Python package: `pip install .` into a venv, and `cmake --install`.

Run by ctest (test Python.Install, label python) as
    python3 install_check.py SOURCE_DIR BUILD_DIR INSTALL_PREFIX INSTALL_DIR VERSION
1. A venv made with --system-site-packages (numpy from Debian), then
   pip install --no-build-isolation --no-deps --no-index SOURCE_DIR, the extension taken as built
   in BUILD_DIR (SCOLEID_BUILD_DIR, SCOLEID_NO_BUILD): `import scoleid` from elsewhere gives
   VERSION from the venv.
2. cmake --install BUILD_DIR --component python into a scratch prefix: the package's files land
   under INSTALL_DIR there and import; and INSTALL_PREFIX/INSTALL_DIR, where the real install goes,
   is on the system interpreter's own sys.path (no PYTHONPATH needed).
Exit 0 when all hold; the first failure is printed.
"""
import os
import subprocess
import sys
import tempfile


def run(args, **kw):
    r = subprocess.run(args, capture_output=True, text=True, **kw)
    if r.returncode != 0:
        sys.exit("FAILED: %s\n%s%s" % (" ".join(args), r.stdout[-4000:], r.stderr[-4000:]))
    return r.stdout


def main():
    source, build, prefix, install_dir, version = sys.argv[1:6]
    with tempfile.TemporaryDirectory() as tmp:
        venv = os.path.join(tmp, "venv")
        run([sys.executable, "-m", "venv", "--system-site-packages", venv])
        py = os.path.join(venv, "bin", "python")
        # The extension as ctest's build made it (SCOLEID_NO_BUILD: no CMake run beside the tests).
        env = dict(os.environ, SCOLEID_BUILD_DIR=build, SCOLEID_NO_BUILD="1", PIP_NO_CACHE_DIR="1",
                   PIP_DISABLE_PIP_VERSION_CHECK="1")
        env.pop("PYTHONPATH", None)
        run([py, "-m", "pip", "install", "--no-build-isolation", "--no-deps", "--no-index", source], env=env)
        out = run([py, "-c", "import scoleid; print(scoleid.__version__); print(scoleid.__file__); "
                   "print(sorted(scoleid.builtin_scenarios())[0])"], cwd=tmp, env=env).split("\n")
        print("venv:", out[:3])
        assert out[0] == version, "version %r, expected %r" % (out[0], version)
        assert os.path.realpath(out[1]).startswith(os.path.realpath(venv)), "imported from %s, not the venv" % out[1]
        shipped = os.listdir(os.path.dirname(out[1]))
        assert "__init__.pyi" in shipped and "py.typed" in shipped, shipped
        run([py, "-m", "pip", "uninstall", "-y", "scoleid"], env=env)

        scratch = os.path.join(tmp, "prefix")
        run(["cmake", "--install", build, "--component", "python", "--prefix", scratch])
        site = os.path.join(scratch, install_dir)
        files = sorted(os.listdir(os.path.join(site, "scoleid")))
        print("cmake --install:", install_dir, files)
        assert any(f.startswith("_core") for f in files) and "__init__.py" in files and "__init__.pyi" in files, files
        env = dict(os.environ, PYTHONPATH=site)
        out = run([sys.executable, "-c", "import scoleid; print(scoleid.__version__, scoleid.__file__)"], cwd=tmp, env=env)
        assert out.split()[0] == version and out.split()[1].startswith(site), out
    target = os.path.normpath(os.path.join(prefix, install_dir))
    env = dict(os.environ)
    env.pop("PYTHONPATH", None)
    path = run([sys.executable, "-c", "import sys; print('\\n'.join(sys.path))"], env=env).split("\n")
    print("the configured install goes to", target, "- on sys.path:", target in path)
    assert target in path, "%s is not on %s's sys.path %s" % (target, sys.executable, path)
    print("OK")


if __name__ == "__main__":
    main()
